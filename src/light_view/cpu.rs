//! The light view's stages on all CPU cores: the receiver map, then only
//! what the method reads (occluder layers by depth peeling, or the occluder
//! triangles), then the method's shading.

use super::stages::{LightMaps, LightViewStages};
use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{light_space_triangles, DepthInUnit, FramedScene, MapSettings};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::memory::{check_fits, map_bytes};
use crate::methods::{bounded, shade_map, Input, Method, ShadowInputs};
use crate::raster::{rasterize, Prepared};
use crate::timing::{Stopwatch, Timings};

/// The light view's stages on the CPU.
pub struct CpuLightView;

impl LightViewStages for CpuLightView {
    const BACKEND: Backend = Backend::Cpu;

    fn check_meshes(&self, _s: &MapSettings) -> Result<()> {
        Ok(())
    }

    fn meshes(
        &mut self,
        f: &FramedScene,
        (occluder_faces, receiver_faces): (&[[u32; 3]], &[[u32; 3]]),
        s: &MapSettings,
        sw: &mut Stopwatch,
    ) -> Result<LightMaps> {
        let receiver = rasterize(&f.grid, &f.rec_ls, receiver_faces, f.near, false).nearest;
        sw.lap("raster_receivers");
        // Only what the method reads: occluder maps for the map methods,
        // light-space triangles for the ray-traced one.
        let mut middle: Vec<Vec<f32>> = vec![];
        let triangles = s.method.reads_input(Input::OccluderTriangles).then(|| {
            let t = light_space_triangles(&f.occ_ls, occluder_faces);
            sw.lap("triangles");
            t
        });
        let occ = s.method.reads_input(Input::OccluderLayers).then(|| {
            // One set-up serves every layer: front and back in one
            // traversal, then one traversal per peeled layer (passes >= 3).
            let prepared = Prepared::new(&f.occluder_grid, &f.occ_ls, occluder_faces, f.near);
            let o = prepared.nearest_farthest(s.passes >= 2);
            for k in 0..s.passes.saturating_sub(2) as usize {
                let next = prepared.peel(if k == 0 { &o.nearest } else { &middle[k - 1] });
                middle.push(next);
            }
            sw.lap("raster_occluders");
            o
        });
        let mut layers: Vec<&[f32]> = vec![];
        if let Some(o) = &occ {
            layers.push(&o.nearest);
            layers.extend(middle.iter().map(|m| m.as_slice()));
            if let Some(back) = o.farthest.as_deref() {
                layers.push(back);
            }
        }
        let inputs = ShadowInputs {
            grid: f.grid,
            occluder_grid: f.occluder_grid,
            // The hard shadow map where a plan says every penumbra is under
            // half a texel (the point-light path of shade_map).
            light_shape: if s.hard {
                LightShape::POINT
            } else {
                f.light_shape
            },
            receiver: &receiver,
            occluder_layers: layers,
            occluder_triangles: triangles.as_deref(),
        };
        let visibility = bounded(s.method, &inputs, None, "occluder_resolution", || {
            shade_map(s.method, &inputs)
        })?;
        sw.lap("shadow");
        let (front, back) = match occ {
            Some(o) => (Some(o.nearest), o.farthest),
            None => (None, None),
        };
        Ok(LightMaps {
            visibility,
            receiver,
            front,
            middle,
            back,
        })
    }

    fn check_depth(&self, _method: Method, _grid: &MapGrid, _og: &MapGrid) -> Result<()> {
        Ok(())
    }

    fn reserve_depth(
        &self,
        _method: Method,
        (grid, occluder_grid): (&MapGrid, &MapGrid),
        layers: usize,
        unit: f64,
    ) -> Result<()> {
        // Visibility, the kernels' 1/depth layers, and the copies in the
        // kernels' unit (only far from 1).
        let copies = if unit == 1.0 { 0 } else { 1 };
        check_fits(
            "receiver_depth",
            &format!("{}x{} maps", grid.width, grid.height),
            map_bytes(grid.len(), 1 + copies)
                + map_bytes(occluder_grid.len(), layers * (1 + copies)),
        )
    }

    fn depth(
        &mut self,
        (grid, occluder_grid): (&MapGrid, &MapGrid),
        d: &DepthInUnit,
        method: Method,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        let mut layers: Vec<&[f32]> = vec![&d.front];
        if let Some(b) = &d.back {
            layers.push(b);
        }
        let inputs = ShadowInputs {
            grid: *grid,
            occluder_grid: *occluder_grid,
            light_shape: d.light_shape,
            receiver: &d.receiver,
            occluder_layers: layers,
            occluder_triangles: None,
        };
        let v = bounded(method, &inputs, None, "occluder_resolution", || {
            shade_map(method, &inputs)
        })?;
        sw.lap("shadow");
        Ok(v)
    }

    fn timings(&mut self, host: Timings) -> Timings {
        host
    }
}
