//! Per-stage device times: timestamp queries around each compute pass where
//! the adapter has them, else the wall time of the whole submission.

use super::context::Gpu;
use std::cell::RefCell;

pub struct StageTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    names: RefCell<Vec<&'static str>>,
    capacity: u32,
}

impl StageTimer {
    /// A timer for up to `stages` passes.
    pub fn new(g: &Gpu, stages: u32) -> StageTimer {
        let queries = g.timestamps.then(|| {
            let set = g.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("stage timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * stages,
            });
            let resolve = g.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: 16 * stages as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (set, resolve)
        });
        StageTimer {
            queries,
            names: RefCell::new(Vec::new()),
            capacity: stages,
        }
    }

    /// The descriptor of the next pass, named `name` in the timings.
    pub fn pass(&self, name: &'static str) -> wgpu::ComputePassDescriptor<'_> {
        let mut names = self.names.borrow_mut();
        let k = names.len() as u32;
        assert!(k < self.capacity, "StageTimer: more passes than stages");
        names.push(name);
        wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: self.queries.as_ref().map(|(set, _)| {
                wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(2 * k),
                    end_of_pass_write_index: Some(2 * k + 1),
                }
            }),
        }
    }

    /// Bytes the timestamps take in the readback buffer.
    pub fn bytes(&self) -> u64 {
        if self.queries.is_some() {
            16 * self.names.borrow().len() as u64
        } else {
            0
        }
    }

    /// Records the copy of the timestamps into `staging` at `offset`.
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder, staging: &wgpu::Buffer, offset: u64) {
        if let Some((set, resolve)) = &self.queries {
            let n = self.names.borrow().len() as u32;
            enc.resolve_query_set(set, 0..2 * n, resolve, 0);
            enc.copy_buffer_to_buffer(resolve, 0, staging, offset, 16 * n as u64);
        }
    }

    /// Seconds per stage ("gpu_" + the pass name) from the read-back bytes,
    /// or the submission's wall time as one "gpu" stage.
    pub fn read(&self, g: &Gpu, bytes: &[u8], wall: f64) -> Vec<(&'static str, f64)> {
        if self.queries.is_none() {
            return vec![("gpu", wall)];
        }
        let period_s = g.queue.get_timestamp_period() as f64 * 1e-9;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        self.names
            .borrow()
            .iter()
            .enumerate()
            .map(|(k, &name)| {
                let dt = ticks[2 * k + 1].wrapping_sub(ticks[2 * k]) as f64 * period_s;
                (gpu_stage_name(name), dt)
            })
            .collect()
    }
}

/// Timing names are static: the device stages get a "gpu_" prefix.
fn gpu_stage_name(name: &'static str) -> &'static str {
    match name {
        "first_hits" => "gpu_first_hits",
        "raster_receivers" => "gpu_raster_receivers",
        "raster_occluders" => "gpu_raster_occluders",
        "row_stats" => "gpu_row_stats",
        "shadow" => "gpu_shadow",
        "smoothie_buffer" => "gpu_smoothie_buffer",
        "blur" => "gpu_blur",
        _ => name,
    }
}

/// `timings` with the stages named more than once (a call of several
/// submissions: "encode", "device", "readback", "upload", or "gpu" without
/// timestamps) summed into the first of each name.
pub fn merged(timings: crate::timing::Timings) -> crate::timing::Timings {
    let mut out: crate::timing::Timings = Vec::with_capacity(timings.len());
    for (name, t) in timings {
        match out.iter_mut().find(|(n, _)| *n == name) {
            Some((_, sum)) => *sum += t,
            None => out.push((name, t)),
        }
    }
    out
}
