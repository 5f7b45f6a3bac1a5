//! Depth maps the user rendered -> visibility on the GPU: the maps go up in
//! one buffer (receiver, front, back), the method's shading stage runs
//! (`super::kernel`, `GpuKernel::light_view`, without triangles), and the
//! visibility comes back in one readback. A kernel that waits for the
//! layers' corners (bitmask with closed gaps) has them made on the CPU from
//! the maps given (stage "corners").

use super::context::gpu;
use super::dispatch::upload;
use super::gather;
use super::method_kernel::{run_stage, still_waits, LightViewInputs};
use super::readback::{visibility, with_error_scopes};
use super::refusals::{check_side, point_light_on_gpu};
use super::shading::check_size;
use crate::error::Result;
use crate::frame::DepthInUnit;
use crate::geom::light::MapGrid;
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// What the GPU refuses of depth maps before any work: a method it has no
/// kernel for, a map side beyond its fixed-point coordinates.
pub(crate) fn check(method: Method, grid: &MapGrid, occluder_grid: &MapGrid) -> Result<()> {
    super::kernel(method).check(method)?;
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
    // The occluders' largest 1/depth (the depths are checked > 0).
    let w_max = front
        .iter()
        .chain(back.unwrap_or(&[]))
        .fold(0f64, |m, &z| m.max(1.0 / z as f64));
    let kernel = super::kernel(method);
    let inputs = LightViewInputs {
        grid,
        occluder_grid,
        light_shape,
        layers: n_layers,
        w_max,
        occluders: None,
        corners: None,
    };
    // Bitmask's connected micro-quads: their corners, on the CPU.
    let corners;
    let make = match kernel.light_view(g, method, inputs)? {
        Some(make) => make,
        None => {
            let layers: Vec<&[f32]> = std::iter::once(front).chain(back).collect();
            corners = gather::layer_corners(&layers, occluder_grid);
            sw.lap("corners");
            let with_corners = LightViewInputs {
                corners: Some(&corners),
                ..inputs
            };
            kernel
                .light_view(g, method, with_corners)?
                .ok_or_else(still_waits)?
        }
    };
    // The maps as the shaders read them: f32 bits, receiver first.
    let mut words: Vec<u32> =
        Vec::with_capacity(grid.len() + n_layers as usize * occluder_grid.len());
    words.extend(receiver.iter().map(|z| z.to_bits()));
    words.extend(front.iter().map(|z| z.to_bits()));
    words.extend(back.unwrap_or(&[]).iter().map(|z| z.to_bits()));
    let out = with_error_scopes(g, || {
        let maps = upload(&g.device, "maps", &words);
        let shading = make()?;
        sw.lap("upload");
        let out = run_stage(g, shading.as_ref(), &maps, "softshadow from depth", sw)?;
        shading.check(&out.buffers[1..])?;
        Ok(out)
    })?;
    let v = visibility(&out.buffers[0])?;
    Ok((v, out.device_timings))
}
