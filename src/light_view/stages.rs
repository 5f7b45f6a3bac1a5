//! The light view's stages: the interface both backends implement and what
//! it returns (see `mod.rs`).

use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{DepthInUnit, FramedScene, MapSettings};
use crate::geom::light::MapGrid;
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// The light-view maps of a framed scene and the visibility read from them,
/// in the kernels' depth unit.
pub struct LightMaps {
    pub visibility: Vec<f32>,
    pub receiver: Vec<f32>,
    /// The occluder maps; None for methods that trace triangles instead.
    pub front: Option<Vec<f32>>,
    /// Peeled layers between front and back (passes >= 3), nearest first.
    pub middle: Vec<Vec<f32>>,
    pub back: Option<Vec<f32>>,
}

/// The stages of the light view on one backend.
pub trait LightViewStages {
    /// The backend the configs resolve for.
    const BACKEND: Backend;

    /// Refuses, before any work, a mesh call this backend cannot run.
    fn check_meshes(&self, s: &MapSettings) -> Result<()>;

    /// The receiver map, the occluder layers or triangles the method reads,
    /// and the visibility of every receiver texel.
    fn meshes(
        &mut self,
        f: &FramedScene,
        faces: (&[[u32; 3]], &[[u32; 3]]),
        s: &MapSettings,
        sw: &mut Stopwatch,
    ) -> Result<LightMaps>;

    /// Refuses, before any work, depth maps this backend cannot shade.
    fn check_depth(&self, method: Method, grid: &MapGrid, occluder_grid: &MapGrid) -> Result<()>;

    /// Refuses depth maps whose working set would not fit (`layers`
    /// occluder maps; `unit` the kernels' depth unit: maps are copied when
    /// it is not 1).
    fn reserve_depth(
        &self,
        method: Method,
        grids: (&MapGrid, &MapGrid),
        layers: usize,
        unit: f64,
    ) -> Result<()>;

    /// The visibility of every receiver texel of depth maps in the kernels'
    /// unit.
    fn depth(
        &mut self,
        grids: (&MapGrid, &MapGrid),
        d: &DepthInUnit,
        method: Method,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>>;

    /// The call's stage times: the host's laps `host` with the device's.
    fn timings(&mut self, host: Timings) -> Timings;
}
