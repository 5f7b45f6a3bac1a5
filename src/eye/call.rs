//! What the eye view's stages read and return: the call (meshes, light,
//! camera, method, biases, backend) and the image (the G-buffer, the
//! visibility, the map methods' maps, timings). Shared by the CPU stages,
//! their GPU twins and the orchestrator (`crate::pipeline::eye_view`).

use super::gbuffer::GBuffer;
use super::maps::{Bias, EyeMaps};
use super::prepared::Prepared;
use crate::backend::BackendChoice;
use crate::error_estimate::{Draw, ErrorEstimate};
use crate::geom::camera::Camera;
use crate::geom::light_space::{Light, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::methods::MethodConfig;
use crate::timing::Timings;

/// The most lights one call renders: each is a render of its own (its
/// cost bounded as one light's is), so the call's bound is this many times
/// one light's.
pub const MAX_LIGHTS: usize = 32;

/// An image to render.
#[derive(Debug, Clone, Copy)]
pub struct EyeCall<'a> {
    pub meshes: &'a [MeshRef<'a>],
    pub light: &'a Light,
    pub camera: &'a Camera,
    pub method: MethodConfig,
    /// The light-view maps' (W, H); `None`: from the pixels' footprint.
    pub map_resolution: Option<(i64, i64)>,
    pub bias: Bias,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
    /// Estimate the result's error from exact rays at a subset of the
    /// pixels drawn as it says (`estimate.rs`); None: no estimate.
    pub estimate_error: Option<Draw>,
    /// What earlier calls on these meshes built and kept (`prepared.rs`),
    /// read and filled by this one; None: everything is built for this
    /// call alone.
    pub prepared: Option<&'a Prepared>,
    /// The first hits of this camera on these meshes, from another light's
    /// run of the same call (several lights share them); None: computed.
    pub gbuffer: Option<&'a GBuffer>,
}

impl EyeCall<'_> {
    /// The option that sizes the call's occluder maps, which a refusal of
    /// their cost names: the method's own `occluder_resolution` where set,
    /// else `map_resolution` (set, or fitted to the pixels).
    pub fn map_size_arg(&self) -> &'static str {
        if self.method.occluder_resolution().is_some() {
            "occluder_resolution"
        } else {
            "map_resolution"
        }
    }
}

/// A rendered image.
#[derive(Debug, Clone)]
pub struct EyeImage {
    pub gbuffer: GBuffer,
    /// (H, W) visibility; 1 where no surface.
    pub visibility: Vec<f32>,
    /// (H, W) the share of the light's irradiance each pixel's surface sees
    /// (each light point weighted by cos θ cos θ' / r²: shading.rs), where
    /// the method measured it (`exact` on the CPU); None: the shading takes
    /// `visibility`.
    pub weighted: Option<Vec<f32>>,
    /// The map methods' light-view maps (None for `exact`).
    pub maps: Option<EyeMaps>,
    /// The light space they are in.
    /// The light space they are in (None for a sphere, which has none:
    /// geom/sphere_light.rs).
    pub light_space: Option<LightSpace>,
    pub timings: Timings,
    /// The error estimate, when the call asked for one.
    pub estimate: Option<ErrorEstimate>,
}
