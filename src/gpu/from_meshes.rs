//! The light view's maps and visibility on the GPU (`GpuLightView::meshes`),
//! every per-texel stage on the
//! device: the set-up triangles go up once, the receiver map, the occluder
//! layers (front, peeled, back), their row statistics and the method's
//! shading run in one command buffer, and the maps and the visibility come
//! back in one readback.
//!
//! The shading is the method's kernel's (`super::kernel`,
//! `GpuKernel::light_view`), recorded after the maps. On the CPU stay the
//! f64 work WGSL cannot do: the light-space transform, the extent fit and
//! the triangle set-up (clip, project, snap), and the kernel's own CPU part
//! (Smoothies' steps 2-3). A kernel that waits for the maps' corners
//! (bitmask with closed gaps, whose micro-quads' corners the CPU kernel's
//! own function makes) takes two submissions: the maps (read back), then,
//! after the corners (stage "corners") go up, the shading.

use super::context::gpu;
use super::dispatch::storage;
use super::gather;
use super::method_kernel::{run_stage, still_waits, LightViewInputs};
use super::raster::{GpuTri, RasterInput};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::refusals::check_side;
use super::shading::check_size;
use super::timing::StageTimer;
use crate::error::Result;
use crate::frame::{FramedScene, MapSettings};
use crate::light_view::LightMaps;
use crate::raster::setup_triangles;
use crate::timing::{Stopwatch, Timings};

/// What the GPU refuses of a mesh call before any work: a method it has
/// no kernel for, a map side beyond its fixed-point coordinates.
pub(crate) fn check(s: &MapSettings) -> Result<()> {
    super::kernel(s.method).check(s.method)?;
    check_side("resolution", (s.width, s.height))?;
    if let Some(o) = s.occluder_resolution {
        check_side("occluder_resolution", o)?;
    }
    Ok(())
}

/// The maps and the visibility of a framed scene on the device
/// (`light_view::LightViewStages::meshes`), and the device's stage times.
pub(crate) fn maps(
    f: &FramedScene,
    (occluder_faces, receiver_faces): (&[[u32; 3]], &[[u32; 3]]),
    s: &MapSettings,
    sw: &mut Stopwatch,
) -> Result<(LightMaps, Timings)> {
    let traced = s.method.traces();
    let FramedScene {
        occ_ls,
        rec_ls,
        grid,
        occluder_grid,
        near,
        light_shape,
        ..
    } = f;
    let (grid, occluder_grid, near, light_shape) = (*grid, *occluder_grid, *near, *light_shape);
    let g = gpu()?;
    // Occluder depth layers in `maps` after the receiver's (none when traced).
    let layers = if traced { 0 } else { s.passes };
    let passes = layers as usize;
    check_size(g, s.method, &grid, &occluder_grid, layers)?;
    let rec_tris: Vec<GpuTri> = setup_triangles(&grid, rec_ls, receiver_faces, near)
        .iter()
        .map(GpuTri::from_setup)
        .collect();
    let occ_tris: Vec<GpuTri> = if traced {
        vec![]
    } else {
        setup_triangles(&occluder_grid, occ_ls, occluder_faces, near)
            .iter()
            .map(GpuTri::from_setup)
            .collect()
    };
    // The occluders' largest 1/depth, from their vertices in front of the near plane.
    let w_max = occ_ls.iter().fold(0f64, |m, q| m.max(1.0 / q.z.max(near)));
    let kernel = super::kernel(s.method);
    let inputs = LightViewInputs {
        grid: &grid,
        occluder_grid: &occluder_grid,
        light_shape,
        layers,
        w_max,
        occluders: Some((occ_ls, occluder_faces)),
        corners: None,
    };
    // The kernel's CPU part (Smoothies: steps 2-3).
    let make = kernel.light_view(g, s.method, inputs)?;
    sw.lap("setup");
    let maps_len = grid.len() + passes * occluder_grid.len();
    let out = with_error_scopes(g, || {
        // None: the shading waits for the maps' corners.
        let shading = make.map(|make| make()).transpose()?;
        let maps = storage(
            &g.device,
            "maps",
            maps_len as u64 * 4,
            wgpu::BufferUsages::COPY_SRC,
        );
        let tris = RasterInput::upload(g, &rec_tris, &occ_tris);
        sw.lap("upload");
        let timer = StageTimer::new(g, 4);
        let mut enc = g
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("softshadow"),
            });
        tris.record(g, &mut enc, &timer, &maps, &grid, &occluder_grid, layers);
        let mut sources = vec![(&maps, maps_len as u64 * 4)];
        if let Some(sh) = &shading {
            sh.record(g, &mut enc, &timer, &maps)?;
            sources.extend(sh.outputs());
        }
        let mut out = submit_and_read(g, enc, &timer, &sources, sw)?;
        let shading = match shading {
            Some(sh) => sh,
            None => {
                // The corners from the maps read back, then the shading.
                let m = words(&out.buffers[0]);
                let occ: &[f32] = bytemuck::cast_slice(&m[grid.len()..]);
                let layer_maps: Vec<&[f32]> = occ.chunks_exact(occluder_grid.len()).collect();
                let corners = gather::layer_corners(&layer_maps, &occluder_grid);
                sw.lap("corners");
                let with_corners = LightViewInputs {
                    corners: Some(&corners),
                    ..inputs
                };
                let make = kernel
                    .light_view(g, s.method, with_corners)?
                    .ok_or_else(still_waits)?;
                let sh = make()?;
                sw.lap("upload");
                let shaded = run_stage(g, sh.as_ref(), &maps, "softshadow quads", sw)?;
                out.buffers.extend(shaded.buffers);
                out.device_timings.extend(shaded.device_timings);
                sh
            }
        };
        shading.check(&out.buffers[2..])?;
        Ok(out)
    })?;
    let maps = words(&out.buffers[0]);
    let visibility = visibility(&out.buffers[1])?;
    let rec_len = grid.len();
    let occ_len = occluder_grid.len();
    let map_of = |k: usize, empty_zero: bool| -> Vec<f32> {
        let off = rec_len + k * occ_len;
        maps[off..off + occ_len]
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
    let receiver: Vec<f32> = maps[..rec_len].iter().map(|&b| f32::from_bits(b)).collect();
    let front = (!traced).then(|| map_of(0, false));
    let middle: Vec<Vec<f32>> = (1..passes.saturating_sub(1))
        .map(|k| map_of(k, false))
        .collect();
    // The farthest layer starts at 0 (before the atomicMax): 0 means empty.
    let back = (passes >= 2).then(|| map_of(passes - 1, true));
    Ok((
        LightMaps {
            visibility,
            receiver,
            front,
            middle,
            back,
        },
        out.device_timings,
    ))
}
