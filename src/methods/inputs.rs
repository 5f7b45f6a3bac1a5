//! What every method reads and writes, apart from the registry that picks
//! one (`mod.rs`): the methods' modules read these types, the registry
//! reads the methods.

use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::plane_gradient::Plane;
use crate::trace::ray_start::RayStart;
use glam::{DVec3, Vec3};

/// What every method reads: the light-view maps and the light's size.
#[derive(Debug, Clone)]
pub struct ShadowInputs<'a> {
    /// The output grid, which the receiver map shares.
    pub grid: MapGrid,
    /// The occluder maps' grid: the same extent, its own resolution (coarser
    /// occluder maps cost less; the paper notes large lights need fewer texels).
    pub occluder_grid: MapGrid,
    /// The light's shape in its plane (geom/light_shape/), in depth units.
    pub light_shape: LightShape,
    /// Receiver planar depth per texel, `inf` where there is no receiver.
    pub receiver: &'a [f32],
    /// Occluder depth layers: the front (nearest) map, then the back (farthest) one.
    pub occluder_layers: Vec<&'a [f32]>,
    /// Occluder triangles in light space, for the methods that trace them.
    pub occluder_triangles: Option<&'a [[Vec3; 3]]>,
}

/// A receiver point in light space: tangent coordinates and planar depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightPoint {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// The eye view's visible points as a map method shades them (`eye/maps.rs`).
#[derive(Debug, Clone, Copy)]
pub struct EyePoints<'a> {
    /// The points moved by the biases, kernel light space.
    pub points: &'a [LightPoint],
    /// Each point's tangent plane on the grid (for the kernels that test
    /// their texels on it, `Kernel::TESTS_PLANES`); else empty.
    pub planes: &'a [Plane],
    /// Where the shaded image is asked for under an area light, each
    /// point's surface and ray start (the unbiased point): the kernel's
    /// weighted visibility is taken from it, where it has one.
    pub starts: Option<&'a [Option<RayStart>]>,
    /// Every mesh, in kernel light space: the vertices and the faces
    /// (every mesh is an occluder in the eye view).
    pub verts: &'a [DVec3],
    pub faces: &'a [[u32; 3]],
}

/// The interface of a shadow method.
pub trait ShadowMethod: Sync {
    /// Visibility of the light (fraction of its area) for every receiver texel;
    /// 1 where there is no receiver. Row-major (H, W).
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32>;
    /// Visibility at receiver points given in light space.
    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32>;
    /// Visibility at the eye view's points, and beside it their weighted
    /// visibility (the share of each point's irradiance its visible part
    /// of the light gives) where the kernel has one and `eye.starts` asks
    /// for it. By default the plain visibility at the points, no weights.
    fn visibility_eye(
        &self,
        inputs: &ShadowInputs,
        eye: &EyePoints,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        (self.visibility_points(inputs, eye.points), None)
    }
}

/// What a method reads besides the receivers: the pipeline builds only that.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Input {
    /// Light-view depth layers of the occluders (front, peeled, back).
    OccluderLayers,
    /// The occluder triangles in light space.
    OccluderTriangles,
    /// A camera: the eye view's visible points (what ShadowMapping focuses,
    /// warps and blurs for).
    Camera,
    /// Every mesh's triangles in world space, rasterized into the method's
    /// own shadow map.
    SceneTriangles,
}

impl Input {
    /// The name the capabilities table gives it.
    pub fn name(self) -> &'static str {
        match self {
            Input::OccluderLayers => "occluder_layers",
            Input::OccluderTriangles => "occluder_triangles",
            Input::Camera => "camera",
            Input::SceneTriangles => "scene_triangles",
        }
    }
}

/// Whether a receiver depth (a texel's, a point's) holds a surface in
/// front of the light: what the cost limits count receivers by.
#[inline]
pub fn is_receiver(z: f32) -> bool {
    z.is_finite() && z > 0.0
}

/// The receivers' worth of work every call may spend, however few it
/// shades (a 640x480 image's): the floor of the cost limits that grow with
/// the receivers (`gather::work::visit_limit`, `pcss::READS_PER_RECEIVER`).
pub const MIN_RECEIVERS: usize = 640 * 480;
