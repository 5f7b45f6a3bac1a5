//! Meshes -> light-view maps -> visibility, every per-texel stage on the
//! device: the set-up triangles go up once, the receiver map, the occluder
//! layers (front, peeled, back), their row statistics and the method's
//! shading run in one command buffer, and the maps and the visibility come
//! back in one readback.
//!
//! On the CPU stay the f64 work WGSL cannot do: the light-space transform,
//! the extent fit and the triangle set-up (clip, project, snap).

use super::context::{gpu, Gpu};
use super::gather::{self, GatherBuffers, GatherParams, RowSpan};
use super::raster::{
    peel_factor, tiles, GpuTri, RasterParams, RasterPipelines, RasterTile, INF_BITS, NONE,
};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::light::{MapGrid, RectLight};
use crate::mesh::MeshRef;
use crate::pipeline::{frame_scene, FramedScene, MapSettings, ShadowResult, Stopwatch};
use crate::raster::setup_triangles;
use wgpu::util::DeviceExt;

/// The largest map side on the GPU: fixed-point coordinates ((side + 2
/// guard bands) x 256) must fit in i32 for the shader's edge functions,
/// texel offsets below 2^16 keep the depth plane's limb products exact, and
/// a row's statistics (one invocation a row) stay within lavapipe's 65535
/// loop iterations.
pub const MAX_SIDE: usize = 1 << 14;

fn check_side(arg: &str, g: (usize, usize)) -> Result<()> {
    if g.0 > MAX_SIDE || g.1 > MAX_SIDE {
        return Err(Error::too_large(
            arg,
            format!(
                "{}x{} exceeds the GPU backend's largest side {MAX_SIDE}; use backend=\"cpu\"",
                g.0, g.1
            ),
        ));
    }
    Ok(())
}

fn storage(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
    extra: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | extra,
        mapped_at_creation: false,
    })
}

/// A read-only storage buffer holding `items`; a binding must not be
/// empty, so an empty list gets one unused zeroed item.
fn upload<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, items: &[T]) -> wgpu::Buffer {
    let one = [T::zeroed()];
    let data: &[T] = if items.is_empty() { &one } else { items };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(data),
        usage: wgpu::BufferUsages::STORAGE,
    })
}

/// Tangent coordinates the shaders read, computed in f64 like the CPU
/// kernels' tables (so both sides start from the same f32 values).
struct Axes {
    data: Vec<f32>,
    rec_x: u32,
    rec_y: u32,
    col_x0s: u32,
    row_y: u32,
}

fn axes(grid: &MapGrid, og: &MapGrid, light_size: [f64; 2]) -> Axes {
    let (hw, _) = og.half_texel();
    let mut data = Vec::new();
    let rec_x = data.len() as u32;
    data.extend((0..grid.width).map(|i| grid.x_of(i) as f32));
    let rec_y = data.len() as u32;
    data.extend((0..grid.height).map(|j| grid.y_of(j) as f32));
    let col_x0s = data.len() as u32;
    data.extend((0..og.width).map(|i| ((og.x_of(i) - hw) * 2.0 / light_size[0]) as f32));
    let row_y = data.len() as u32;
    data.extend((0..og.height).map(|j| og.y_of(j) as f32));
    Axes {
        data,
        rec_x,
        rec_y,
        col_x0s,
        row_y,
    }
}

fn gather_params(
    grid: &MapGrid,
    og: &MapGrid,
    light_size: [f64; 2],
    n_layers: u32,
    ax: &Axes,
) -> GatherParams {
    let (hw, hh) = og.half_texel();
    // The same f32 values as methods/gather.rs's Kernel::new.
    let inv_half_lx = (2.0 / light_size[0]) as f32;
    GatherParams {
        rec_w: grid.width as u32,
        rec_h: grid.height as u32,
        occ_w: og.width as u32,
        occ_h: og.height as u32,
        n_layers,
        layer0_offset: grid.len() as u32,
        layer_stride: og.len() as u32,
        ax_rec_x: ax.rec_x,
        ax_rec_y: ax.rec_y,
        ax_col_x0s: ax.col_x0s,
        ax_row_y: ax.row_y,
        samples: 0,
        tx: og.tx as f32,
        ty: og.ty as f32,
        hw: hw as f32,
        hh: hh as f32,
        inv_half_lx,
        inv_half_ly: (2.0 / light_size[1]) as f32,
        half_lx: (0.5 * light_size[0]) as f32,
        half_ly: (0.5 * light_size[1]) as f32,
        wx: 2.0 * hw as f32 * inv_half_lx,
        ..Default::default()
    }
}

/// Soft shadow map from meshes on the GPU; the same result type, maps and
/// stage names (plus the device's) as `pipeline::from_meshes`.
pub fn from_meshes(
    occluders: MeshRef,
    receivers: MeshRef,
    light: &RectLight,
    s: &MapSettings,
) -> Result<ShadowResult> {
    gather::check_method(s.method)?;
    check_side("resolution", (s.width, s.height))?;
    if let Some(o) = s.occluder_resolution {
        check_side("occluder_resolution", o)?;
    }
    let g = gpu()?;
    let mut sw = Stopwatch::new();
    let FramedScene {
        occ_ls,
        rec_ls,
        grid,
        occluder_grid,
        near,
    } = frame_scene(&occluders, &receivers, light, s, &mut sw)?;
    let passes = s.passes as usize;
    let texels = grid.len() as u64 + passes as u64 * occluder_grid.len() as u64;
    let bytes = texels * 4;
    // The accumulators: a sum per layer (ssm) or a 256-bit mask (bitmask) per receiver.
    let acc_bytes = gather::accumulator_words(s.method, s.passes) as u64 * grid.len() as u64 * 4;
    if texels >= u32::MAX as u64 || bytes.max(acc_bytes) > g.max_storage_binding {
        return Err(Error::too_large(
            "resolution",
            format!(
                "the maps need {} bytes in one GPU buffer; the device binds at most {}",
                bytes.max(acc_bytes),
                g.max_storage_binding
            ),
        ));
    }
    let rec_tris: Vec<GpuTri> = setup_triangles(&grid, &rec_ls, receivers.faces, near)
        .iter()
        .map(GpuTri::from_setup)
        .collect();
    let occ_tris: Vec<GpuTri> = setup_triangles(&occluder_grid, &occ_ls, occluders.faces, near)
        .iter()
        .map(GpuTri::from_setup)
        .collect();
    sw.lap("setup");
    let ax = axes(&grid, &occluder_grid, light.size);
    let mut params = gather_params(&grid, &occluder_grid, light.size, passes as u32, &ax);
    if let crate::methods::Method::Bitmask { samples } = s.method {
        params.samples = samples;
    }
    // The occluders' largest 1/depth, from their vertices in front of the near plane.
    let w_max = occ_ls.iter().fold(0f64, |m, q| m.max(1.0 / q.z.max(near)));
    let (rows_per_chunk, chunks) = gather::chunking(&occluder_grid, light.size, w_max, s.method);
    params.rows_per_chunk = rows_per_chunk;
    let out = run(
        g,
        s,
        &grid,
        &occluder_grid,
        &rec_tris,
        &occ_tris,
        &ax,
        &params,
        chunks,
        &mut sw,
    )?;
    let mut timings = sw.timings;
    timings.extend(out.device_timings);
    let rec_len = grid.len();
    let occ_len = occluder_grid.len();
    let map_of = |k: usize, empty_zero: bool| -> Vec<f32> {
        let off = rec_len + k * occ_len;
        out.maps[off..off + occ_len]
            .iter()
            .map(|&b| {
                if empty_zero && b == 0 {
                    f32::INFINITY
                } else {
                    f32::from_bits(b)
                }
            })
            .collect()
    };
    let receiver: Vec<f32> = out.maps[..rec_len]
        .iter()
        .map(|&b| f32::from_bits(b))
        .collect();
    let front = map_of(0, false);
    let middle: Vec<Vec<f32>> = (1..passes.saturating_sub(1))
        .map(|k| map_of(k, false))
        .collect();
    // The farthest layer starts at 0 (before the atomicMax): 0 means empty.
    let back = (passes >= 2).then(|| map_of(passes - 1, true));
    Ok(ShadowResult {
        grid,
        occluder_grid,
        visibility: out.vis,
        receiver,
        occluder_front: Some(front),
        occluder_middle: middle,
        occluder_back: back,
        timings,
    })
}

struct DeviceOutput {
    maps: Vec<u32>,
    vis: Vec<f32>,
    device_timings: Vec<(&'static str, f64)>,
}

/// `run_captured` with the device's errors (out of memory, validation,
/// internal) caught in error scopes and returned as `Error::Gpu`, rather than
/// left to wgpu's default handler, which panics.
#[allow(clippy::too_many_arguments)]
fn run(
    g: &Gpu,
    s: &MapSettings,
    grid: &MapGrid,
    og: &MapGrid,
    rec_tris: &[GpuTri],
    occ_tris: &[GpuTri],
    ax: &Axes,
    params: &GatherParams,
    chunks: u32,
    sw: &mut Stopwatch,
) -> Result<DeviceOutput> {
    let scopes = [
        wgpu::ErrorFilter::OutOfMemory,
        wgpu::ErrorFilter::Validation,
        wgpu::ErrorFilter::Internal,
    ]
    .map(|f| g.device.push_error_scope(f));
    let out = run_captured(g, s, grid, og, rec_tris, occ_tris, ax, params, chunks, sw);
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

#[allow(clippy::too_many_arguments)]
fn run_captured(
    g: &Gpu,
    s: &MapSettings,
    grid: &MapGrid,
    og: &MapGrid,
    rec_tris: &[GpuTri],
    occ_tris: &[GpuTri],
    ax: &Axes,
    params: &GatherParams,
    chunks: u32,
    sw: &mut Stopwatch,
) -> Result<DeviceOutput> {
    let device = &g.device;
    let passes = s.passes;
    let rec_len = grid.len() as u32;
    let occ_len = og.len() as u32;
    let maps_len = rec_len + passes * occ_len;
    let maps = storage(
        device,
        "maps",
        maps_len as u64 * 4,
        wgpu::BufferUsages::COPY_SRC,
    );
    let vis = storage(
        device,
        "visibility",
        rec_len as u64 * 4,
        wgpu::BufferUsages::COPY_SRC,
    );
    let rows = storage(
        device,
        "row spans",
        (passes * og.height as u32) as u64 * 16,
        wgpu::BufferUsages::empty(),
    );
    let layer_w_max = storage(
        device,
        "layer w max",
        passes as u64 * 4,
        wgpu::BufferUsages::COPY_DST,
    );
    let rec_tiles: Vec<RasterTile> = tiles(rec_tris);
    let occ_tiles: Vec<RasterTile> = tiles(occ_tris);
    let rec_buf = upload(device, "receiver triangles", rec_tris);
    let occ_buf = upload(device, "occluder triangles", occ_tris);
    let rec_tile_buf = upload(device, "receiver tiles", &rec_tiles);
    let occ_tile_buf = upload(device, "occluder tiles", &occ_tiles);
    let axes_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("axes"),
        contents: bytemuck::cast_slice(&ax.data),
        usage: wgpu::BufferUsages::STORAGE,
    });
    const _: () = assert!(std::mem::size_of::<RowSpan>() == 16);
    let acc_words = gather::accumulator_words(s.method, passes) as u64 * rec_len as u64;
    let acc = storage(
        device,
        "accumulators",
        acc_words * 4,
        wgpu::BufferUsages::COPY_DST,
    );
    let tables = gather::method_tables(s.method).map(|t| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("method tables"),
            contents: bytemuck::cast_slice(&t),
            usage: wgpu::BufferUsages::STORAGE,
        })
    });
    sw.lap("upload");

    let rp = RasterPipelines::get(device);
    let timer = StageTimer::new(g, 4);
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("softshadow"),
    });
    {
        let mut pass = enc.begin_compute_pass(&timer.pass("raster_receivers"));
        rp.fill(device, &mut pass, &maps, 0, rec_len, INF_BITS);
        rp.raster(
            device,
            &mut pass,
            &maps,
            &rec_buf,
            &rec_tile_buf,
            &RasterParams {
                tile_count: rec_tiles.len() as u32,
                width: grid.width as u32,
                height: grid.height as u32,
                out_offset: 0,
                far_offset: NONE,
                prev_offset: NONE,
                peel_factor: peel_factor(),
                _pad: 0,
            },
        );
    }
    {
        let mut pass = enc.begin_compute_pass(&timer.pass("raster_occluders"));
        let layer = |k: u32| rec_len + k * occ_len;
        // Nearest and peeled layers start at +inf (atomicMin), the farthest at 0 (atomicMax).
        let nearest_layers = if passes >= 2 { passes - 1 } else { 1 };
        rp.fill(
            device,
            &mut pass,
            &maps,
            layer(0),
            occ_len * nearest_layers,
            INF_BITS,
        );
        let far = if passes >= 2 {
            rp.fill(device, &mut pass, &maps, layer(passes - 1), occ_len, 0);
            layer(passes - 1)
        } else {
            NONE
        };
        let base = RasterParams {
            tile_count: occ_tiles.len() as u32,
            width: og.width as u32,
            height: og.height as u32,
            out_offset: layer(0),
            far_offset: far,
            prev_offset: NONE,
            peel_factor: peel_factor(),
            _pad: 0,
        };
        rp.raster(device, &mut pass, &maps, &occ_buf, &occ_tile_buf, &base);
        // Depth peeling: layer k is the nearest surface beyond layer k - 1.
        for k in 1..passes.saturating_sub(1) {
            rp.raster(
                device,
                &mut pass,
                &maps,
                &occ_buf,
                &occ_tile_buf,
                &RasterParams {
                    out_offset: layer(k),
                    far_offset: NONE,
                    prev_offset: layer(k - 1),
                    ..base
                },
            );
        }
    }
    enc.clear_buffer(&layer_w_max, 0, None);
    enc.clear_buffer(&acc, 0, None);
    let gb = GatherBuffers {
        maps: &maps,
        rows: &rows,
        layer_w_max: &layer_w_max,
        axes: &axes_buf,
        vis: &vis,
        tables: tables.as_ref(),
        acc: &acc,
    };
    {
        let mut pass = enc.begin_compute_pass(&timer.pass("row_stats"));
        gather::record_row_stats(device, &mut pass, s.method, &gb, params)?;
    }
    {
        let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
        gather::record_shade(device, &mut pass, s.method, &gb, params, chunks)?;
    }
    // One readback: the maps, then the visibility, then the timestamps.
    let maps_bytes = maps_len as u64 * 4;
    let vis_bytes = rec_len as u64 * 4;
    let ts_bytes = timer.bytes();
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: maps_bytes + vis_bytes + ts_bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    enc.copy_buffer_to_buffer(&maps, 0, &staging, 0, maps_bytes);
    enc.copy_buffer_to_buffer(&vis, 0, &staging, maps_bytes, vis_bytes);
    timer.resolve(&mut enc, &staging, maps_bytes + vis_bytes);
    let cmd = enc.finish();
    sw.lap("encode");
    let submitted = std::time::Instant::now();
    g.queue.submit([cmd]);
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::gpu(format!("waiting for the device: {e}")))?;
    match rx.try_recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => return Err(Error::gpu(format!("mapping the results: {e}"))),
        Err(_) => return Err(Error::gpu("the results were not mapped after the wait")),
    }
    let device_wall = submitted.elapsed().as_secs_f64();
    sw.lap("device");
    let view = slice
        .get_mapped_range()
        .map_err(|e| Error::gpu(format!("reading the results back: {e}")))?;
    let maps_out: Vec<u32> = bytemuck::cast_slice(&view[..maps_bytes as usize]).to_vec();
    let vis_out: Vec<f32> =
        bytemuck::cast_slice(&view[maps_bytes as usize..(maps_bytes + vis_bytes) as usize])
            .to_vec();
    let device_timings = timer.read(g, &view[(maps_bytes + vis_bytes) as usize..], device_wall);
    drop(view);
    staging.unmap();
    sw.lap("readback");
    if let Some(k) = vis_out.iter().position(|v| !v.is_finite()) {
        return Err(Error::gpu(format!(
            "the device returned a non-finite visibility at texel {k}"
        )));
    }
    Ok(DeviceOutput {
        maps: maps_out,
        vis: vis_out,
        device_timings,
    })
}
