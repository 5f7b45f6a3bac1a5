//! The light view's stages on the GPU (`light_view::LightViewStages`):
//! the maps rasterized and shaded in one submission (`from_meshes.rs`), the
//! user's depth maps shaded (`from_depth.rs`); the device's stage times are
//! kept here until the orchestrator asks for them.

use super::timing::merged;
use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{DepthInUnit, FramedScene, MapSettings};
use crate::geom::light::MapGrid;
use crate::light_view::{LightMaps, LightViewStages};
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// The light view's stages on the GPU.
#[derive(Default)]
pub struct GpuLightView {
    device_timings: Timings,
}

impl LightViewStages for GpuLightView {
    const BACKEND: Backend = Backend::Gpu;

    fn check_meshes(&self, s: &MapSettings) -> Result<()> {
        super::from_meshes::check(s)
    }

    fn meshes(
        &mut self,
        f: &FramedScene,
        faces: (&[[u32; 3]], &[[u32; 3]]),
        s: &MapSettings,
        sw: &mut Stopwatch,
    ) -> Result<LightMaps> {
        if f.light_shape.is_point() {
            return Err(super::refusals::point_light_on_gpu("size"));
        }
        let (maps, t) = super::from_meshes::maps(f, faces, s, sw)?;
        self.device_timings.extend(t);
        Ok(maps)
    }

    fn check_depth(&self, method: Method, grid: &MapGrid, occluder_grid: &MapGrid) -> Result<()> {
        super::from_depth::check(method, grid, occluder_grid)
    }

    fn reserve_depth(
        &self,
        method: Method,
        grids: (&MapGrid, &MapGrid),
        layers: usize,
        _unit: f64,
    ) -> Result<()> {
        super::from_depth::reserve(method, grids, layers)
    }

    fn depth(
        &mut self,
        grids: (&MapGrid, &MapGrid),
        d: &DepthInUnit,
        method: Method,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        let (v, t) = super::from_depth::shade(grids, d, method, sw)?;
        self.device_timings.extend(t);
        Ok(v)
    }

    // Several submissions (closed gaps) time some stages more than once:
    // summed.
    fn timings(&mut self, host: Timings) -> Timings {
        let mut timings = host;
        timings.extend(std::mem::take(&mut self.device_timings));
        merged(timings)
    }
}
