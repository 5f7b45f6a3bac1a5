//! Submission and the one readback: every result buffer is copied into one
//! staging buffer, mapped once; device errors are caught in error scopes.

use super::context::Gpu;
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::timing::Stopwatch;

/// Runs `f` with the device's errors (out of memory, validation, internal)
/// caught in error scopes and returned as `Error::Gpu`, rather than left to
/// wgpu's default handler, which panics.
pub fn with_error_scopes<T>(g: &Gpu, f: impl FnOnce() -> Result<T>) -> Result<T> {
    let scopes = [
        wgpu::ErrorFilter::OutOfMemory,
        wgpu::ErrorFilter::Validation,
        wgpu::ErrorFilter::Internal,
    ]
    .map(|filter| g.device.push_error_scope(filter));
    let out = f();
    let errors: Vec<String> = scopes
        .into_iter()
        .rev()
        .filter_map(|scope| pollster::block_on(scope.pop()))
        .map(|e| e.to_string())
        .collect();
    if !errors.is_empty() {
        return Err(Error::gpu(errors.join("; ")));
    }
    out
}

/// What came back: the bytes of each source buffer, and the device's stage times.
pub struct ReadBack {
    pub buffers: Vec<Vec<u8>>,
    pub device_timings: Vec<(&'static str, f64)>,
}

/// Copies `sources` (buffer, bytes) and the timestamps into one staging
/// buffer, submits `enc`, waits and reads it all back (stages "encode",
/// "device" and "readback" of `sw`).
/// How long a finished submission's results may take to be mapped once the
/// device is idle (another thread may be delivering the callback).
const MAP_WAIT: std::time::Duration = std::time::Duration::from_secs(10);

pub fn submit_and_read(
    g: &Gpu,
    mut enc: wgpu::CommandEncoder,
    timer: &StageTimer,
    sources: &[(&wgpu::Buffer, u64)],
    sw: &mut Stopwatch,
) -> Result<ReadBack> {
    let device = &g.device;
    let total: u64 = sources.iter().map(|(_, n)| n).sum();
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (total + timer.bytes()).max(16),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut offset = 0;
    for (b, n) in sources {
        enc.copy_buffer_to_buffer(b, 0, &staging, offset, *n);
        offset += n;
    }
    timer.resolve(&mut enc, &staging, total);
    let cmd = enc.finish();
    sw.lap("encode");
    let submitted = std::time::Instant::now();
    g.queue.submit([cmd]);
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    // The map callback runs in whichever thread's poll processes it: with
    // several calls sharing the device, another thread's poll may be running
    // it just as ours returns, so wait on the channel, polling again, until
    // it arrives (bounded: a lost mapping is an error, not a hang).
    let deadline = std::time::Instant::now() + MAP_WAIT;
    loop {
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::gpu(format!("waiting for the device: {e}")))?;
        match rx.recv_timeout(std::time::Duration::from_millis(1)) {
            Ok(Ok(())) => break,
            Ok(Err(e)) => return Err(Error::gpu(format!("mapping the results: {e}"))),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout)
                if std::time::Instant::now() < deadline => {}
            Err(_) => return Err(Error::gpu("the results were not mapped after the wait")),
        }
    }
    let device_wall = submitted.elapsed().as_secs_f64();
    sw.lap("device");
    let view = slice
        .get_mapped_range()
        .map_err(|e| Error::gpu(format!("reading the results back: {e}")))?;
    let mut buffers = Vec::with_capacity(sources.len());
    let mut offset = 0usize;
    for (_, n) in sources {
        buffers.push(view[offset..offset + *n as usize].to_vec());
        offset += *n as usize;
    }
    let device_timings = timer.read(g, &view[offset..], device_wall);
    drop(view);
    staging.unmap();
    sw.lap("readback");
    Ok(ReadBack {
        buffers,
        device_timings,
    })
}

/// u32 words from read-back bytes.
pub fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The visibility from read-back bytes, refusing a non-finite value (a
/// device fault must not come back as a silent NaN).
pub fn visibility(bytes: &[u8]) -> Result<Vec<f32>> {
    let v: Vec<f32> = words(bytes).into_iter().map(f32::from_bits).collect();
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(Error::gpu(format!(
            "the device returned a non-finite visibility at texel {k}"
        )));
    }
    Ok(v)
}
