//! Depth maps the user rendered -> visibility on the GPU: the maps go up in
//! one buffer (receiver, front, back), the shading stage runs, and the
//! visibility comes back in one readback. Bitmask with closed gaps makes its
//! corners on the CPU from the maps given (stage "corners") and uploads them.

use super::context::gpu;
use super::dispatch::upload;
use super::gather;
use super::pcss::PcssShading;
use super::readback::{submit_and_read, visibility, with_error_scopes};
use super::refusals::{check_side, point_light_on_gpu};
use super::shading::{check_size, Shading};
use super::timing::StageTimer;
use crate::error::Result;
use crate::frame::{check_depth_inputs, DepthInUnit};
use crate::geom::light::{is_point, MapGrid};
use crate::geom::units::{depth_unit, farthest};
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// `pipeline::from_depth` on the GPU: the same checks, result and stage
/// names (plus the device's).
pub fn from_depth(
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_size: [f64; 2],
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<(Vec<f32>, Timings)> {
    let light_size = check_depth_inputs(
        grid,
        occluder_grid,
        light_size,
        front,
        back,
        receiver,
        method,
    )?;
    if !matches!(method, Method::Pcss { .. }) {
        gather::check_method(method)?;
    }
    // The kernels' depth unit, as on the CPU (see units.rs).
    let d = DepthInUnit::new(
        depth_unit(farthest(receiver)),
        light_size,
        front,
        back,
        receiver,
    )?;
    if is_point(d.light_size) {
        return Err(point_light_on_gpu("light_size"));
    }
    let (light_size, front, back, receiver) = (
        d.light_size,
        &d.front[..],
        d.back.as_deref(),
        &d.receiver[..],
    );
    check_side("receiver_depth", (grid.width, grid.height))?;
    check_side(
        "occluder_depth",
        (occluder_grid.width, occluder_grid.height),
    )?;
    let g = gpu()?;
    let n_layers = 1 + back.is_some() as u32;
    check_size(g, method, grid, occluder_grid, n_layers)?;
    let mut sw = Stopwatch::new();
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
            let sh = PcssShading::maps(g, grid, occluder_grid, light_size, max_taps, off)?;
            sw.lap("upload");
            let timer = StageTimer::new(g, 1);
            let mut enc = g
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("softshadow from depth pcss"),
                });
            sh.record(g, &mut enc, &timer, &maps);
            return submit_and_read(g, enc, &timer, &[(&sh.vis, sh.vis_bytes)], &mut sw);
        }
        let shading = Shading::new(
            g,
            method,
            grid,
            occluder_grid,
            light_size,
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
        submit_and_read(
            g,
            enc,
            &timer,
            &[(&shading.vis, shading.vis_bytes)],
            &mut sw,
        )
    })?;
    let v = visibility(&out.buffers[0])?;
    let mut timings = sw.timings;
    timings.extend(out.device_timings);
    Ok((v, timings))
}
