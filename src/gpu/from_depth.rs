//! Depth maps the user rendered -> visibility on the GPU: the maps go up in
//! one buffer (receiver, front, back), the shading stage runs, and the
//! visibility comes back in one readback. Bitmask with closed gaps makes its
//! corners on the CPU from the maps given (stage "corners") and uploads them.

use super::context::gpu;
use super::dispatch::upload;
use super::gather;
use super::pcss::PcssShading;
use super::readback::{submit_and_read, visibility, with_error_scopes};
use super::refusals::{check_method, check_side, point_light_on_gpu};
use super::shading::{check_size, Shading};
use super::timing::StageTimer;
use crate::error::Result;
use crate::frame::DepthInUnit;
use crate::geom::light::MapGrid;
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// What the GPU refuses of depth maps before any work: a method it has no
/// kernel for, a map side beyond its fixed-point coordinates.
pub(crate) fn check(method: Method, grid: &MapGrid, occluder_grid: &MapGrid) -> Result<()> {
    check_method(method)?;
    check_side("receiver_depth", (grid.width, grid.height))?;
    check_side(
        "occluder_depth",
        (occluder_grid.width, occluder_grid.height),
    )
}

/// Refuses maps the device cannot bind.
pub(crate) fn reserve(
    method: Method,
    (grid, occluder_grid): (&MapGrid, &MapGrid),
    layers: usize,
) -> Result<()> {
    check_size(gpu()?, method, grid, occluder_grid, layers as u32)
}

/// The visibility of depth maps in the kernels' unit on the device
/// (`light_view::LightViewStages::depth`), and the device's stage times.
pub(crate) fn shade(
    (grid, occluder_grid): (&MapGrid, &MapGrid),
    d: &DepthInUnit,
    method: Method,
    sw: &mut Stopwatch,
) -> Result<(Vec<f32>, Timings)> {
    if d.light_shape.is_point() {
        return Err(point_light_on_gpu("light_size"));
    }
    let (light_shape, front, back, receiver) = (
        d.light_shape,
        &d.front[..],
        d.back.as_deref(),
        &d.receiver[..],
    );
    let g = gpu()?;
    let n_layers = 1 + back.is_some() as u32;
    // Bitmask's connected micro-quads: their corners, on the CPU.
    let corners = gather::needs_corners(method).then(|| {
        let layers: Vec<&[f32]> = std::iter::once(front).chain(back).collect();
        let c = gather::layer_corners(&layers, occluder_grid);
        sw.lap("corners");
        c
    });
    // The maps as the shaders read them: f32 bits, receiver first.
    let mut words: Vec<u32> =
        Vec::with_capacity(grid.len() + n_layers as usize * occluder_grid.len());
    words.extend(receiver.iter().map(|z| z.to_bits()));
    words.extend(front.iter().map(|z| z.to_bits()));
    words.extend(back.unwrap_or(&[]).iter().map(|z| z.to_bits()));
    // The occluders' largest 1/depth (the depths are checked > 0).
    let w_max = front
        .iter()
        .chain(back.unwrap_or(&[]))
        .fold(0f64, |m, &z| m.max(1.0 / z as f64));
    let out = with_error_scopes(g, || {
        let maps = upload(&g.device, "maps", &words);
        if let Method::Pcss { max_taps } = method {
            // The front layer follows the receiver map.
            let off = grid.len() as u32;
            let sh = PcssShading::maps(g, grid, occluder_grid, light_shape, max_taps, off)?;
            sw.lap("upload");
            let timer = StageTimer::new(g, 1);
            let mut enc = g
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("softshadow from depth pcss"),
                });
            sh.record(g, &mut enc, &timer, &maps);
            return submit_and_read(g, enc, &timer, &[(&sh.vis, sh.vis_bytes)], sw);
        }
        let shading = Shading::new(
            g,
            method,
            grid,
            occluder_grid,
            light_shape,
            n_layers,
            w_max,
            corners.as_ref(),
        );
        sw.lap("upload");
        let timer = StageTimer::new(g, 2);
        let mut enc = g
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("softshadow from depth"),
            });
        shading.record(g, &mut enc, &timer, &maps)?;
        submit_and_read(g, enc, &timer, &[(&shading.vis, shading.vis_bytes)], sw)
    })?;
    let v = visibility(&out.buffers[0])?;
    Ok((v, out.device_timings))
}
