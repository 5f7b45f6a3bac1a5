//! The end-to-end pipelines on the CPU, one file a stage of the data flow:
//! `frame` (meshes to light space, grids fitted), `from_meshes` (light-view
//! maps rasterized, then shaded), `from_depth` (the user's depth maps shaded),
//! `points` (visibility at world points). Timings are kept per stage.
//! `crate::backend` picks the CPU pipeline or the GPU's.

mod frame;
mod from_depth;
mod from_meshes;
mod from_scene;
mod measure;
mod points;

// The GPU pipelines (and the planner) start from the same framing and checks.
pub(crate) use frame::frame_scene;
#[cfg(feature = "gpu")]
pub(crate) use frame::FramedScene;
pub use frame::Timings;
pub(crate) use frame::{near_plane, scene_stats, Stopwatch};
pub use from_depth::{check_depth, from_depth};
#[cfg(feature = "gpu")]
pub(crate) use from_depth::{check_depth_inputs, DepthInUnit};
pub use from_meshes::{from_meshes, light_space_triangles, ShadowResult};
pub use from_scene::from_scene;
pub(crate) use measure::{layer_tries, thin_features};
pub(crate) use points::shade_points;
pub use points::{receiver_points, sample_points, OccluderSource};

use crate::methods::{Method, MethodConfig};

/// Settings of the mesh pipeline.
#[derive(Debug, Clone, Copy)]
pub struct MapSettings {
    pub width: usize,
    pub height: usize,
    /// Tangent half-extents, or `None` to fit them (see `extent.rs`).
    pub extent: Option<[f64; 2]>,
    /// Resolution of the occluder maps (same extent); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
    pub passes: u32,
    pub method: Method,
    /// Shade the map methods' layers as for a point light (hard shadows),
    /// whatever the light's size: what a plan decides where every penumbra
    /// is under half a texel (`methods/plan.rs`).
    pub hard: bool,
}

impl MapSettings {
    /// The settings of a resolved config (see `MethodConfig::resolve`).
    pub fn new(
        width: usize,
        height: usize,
        extent: Option<[f64; 2]>,
        method: &MethodConfig,
    ) -> MapSettings {
        MapSettings {
            width,
            height,
            extent,
            occluder_resolution: method.occluder_resolution(),
            passes: method.passes(),
            method: method.kernel(),
            hard: false,
        }
    }
}
