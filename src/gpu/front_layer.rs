//! The eye view's one-layer map methods on the device (`pcss`, `smoothies`):
//! what `maps::shade` does for them, split between the CPU and the device.
//!
//! On the CPU, shared with the CPU path: the near plane and the set-up of
//! every mesh's triangles on the grid (`maps::occluder_layers`' front layer)
//! and the biased points with their tangent-plane bounds
//! (`maps::shading_points`). On the device, in one submission: the front
//! layer rasterized by raster.wgsl at offset 0 of the maps buffer, then the
//! method's own `Stage`, one readback of the layer and the visibility.
//! Then `maps::finish` (each point cut to its bound) and the layer in the
//! user's depth, as the CPU's `EyeMaps` hold it.

use super::context::Gpu;
use super::dispatch::storage;
use super::method_kernel::Stage;
use super::raster::{GpuTri, RasterInput};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::maps::{self, LightTriangles, ShadingPoints};
use crate::eye::{Bias, EyeMaps, Framed, MapShading};
use crate::geom::light::MapGrid;
use crate::raster::setup_triangles;
use crate::timing::{Stopwatch, Timings};
use rayon::prelude::*;

/// The CPU's part: the grid, its front layer's triangles and the points.
pub(super) struct FrontLayer {
    pub grid: MapGrid,
    occ_tris: Vec<GpuTri>,
    pub points: ShadingPoints,
}

impl FrontLayer {
    /// Refuses a layer one binding cannot hold, then sets up the triangles
    /// and the biased points.
    pub fn new(
        g: &Gpu,
        f: &Framed,
        tris: &LightTriangles,
        grid: MapGrid,
        bias: &Bias,
        planes: bool,
    ) -> Result<FrontLayer> {
        let bytes = grid.len() as u64 * 4;
        if grid.len() as u64 >= u32::MAX as u64 || bytes > g.max_storage_binding {
            return Err(Error::too_large(
                "map_resolution",
                format!(
                    "the front layer needs {bytes} bytes in one GPU buffer; the device binds at \
                     most {}; use backend=\"cpu\"",
                    g.max_storage_binding
                ),
            ));
        }
        let near = crate::raster::near_plane(&tris.verts);
        let occ_tris = setup_triangles(&grid, &tris.verts, tris.faces, near)
            .iter()
            .map(GpuTri::from_setup)
            .collect();
        let points = f.shading_points(&grid, bias, planes);
        Ok(FrontLayer {
            grid,
            occ_tris,
            points,
        })
    }

    /// The device's part: the layer, then the stage `make` builds (inside
    /// the error scopes, so a failed allocation is an error, not a panic),
    /// reading the layer at offset 0; `stages` timed stages in all; the
    /// visibility per point (and the weighted visibility, where the stage's
    /// visibility buffer holds it after the plain one), the maps and the
    /// device's stage times.
    pub fn shade<S: Stage>(
        self,
        g: &Gpu,
        f: &Framed,
        label: &str,
        stages: u32,
        make: impl FnOnce() -> Result<S>,
        sw: &mut Stopwatch,
    ) -> Result<(MapShading, Timings)> {
        let bytes = self.grid.len() as u64 * 4;
        let out = with_error_scopes(g, || {
            let maps_buf = storage(&g.device, "maps", bytes, wgpu::BufferUsages::COPY_SRC);
            let raster = RasterInput::upload(g, &[], &self.occ_tris);
            let kernel = make()?;
            sw.lap("upload");
            let timer = StageTimer::new(g, stages);
            let mut enc = g
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
            raster.record_occluders(g, &mut enc, &timer, &maps_buf, 0, &self.grid, 1);
            kernel.record(g, &mut enc, &timer, &maps_buf)?;
            let mut sources = vec![(&maps_buf, bytes)];
            sources.extend(kernel.outputs());
            let out = submit_and_read(g, enc, &timer, &sources, sw)?;
            kernel.check(&out.buffers[2..])?;
            Ok(out)
        })?;
        let mut v = visibility(&out.buffers[1])?;
        let n = self.points.bound.len();
        let mut weighted = (v.len() > n).then(|| v.split_off(n));
        maps::finish(&mut v, &self.points.bound);
        if let Some(w) = &mut weighted {
            maps::finish_weighted(w, &self.points.bound);
        }
        let front = words(&out.buffers[0])
            .par_iter()
            .map(|&b| maps::user_depth(&f.space, f.unit, f32::from_bits(b)))
            .collect();
        Ok((
            MapShading {
                visibility: v,
                weighted,
                maps: EyeMaps {
                    grid: self.grid,
                    layers: vec![front],
                },
            },
            out.device_timings,
        ))
    }
}
