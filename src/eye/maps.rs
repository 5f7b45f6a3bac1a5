//! The map methods (`ssm`, `bitmask`, the hard shadow map) in the eye view:
//! light-view occluder layers of every mesh, focused on the visible points
//! (focus.rs), then each pixel shaded at its own surface point, as
//! `ShadowMap.sample` shades points.
//!
//! Self-shadowing. Every mesh is an occluder, so the front layer holds the
//! very surface a pixel sees. A texel of it back-projects, seen from a point
//! a fraction of a texel away, onto much of the light: acne. Two biases,
//! in texels of the map at the point (its tangent width times the point's
//! light depth, or times the orthographic scale for the sun):
//! * normal offset: the point moves `normal_offset` texels along its
//!   geometric normal (toward the camera), off its own micro-patches;
//! * depth bias: then `depth_bias (1 + tan θ)` texels toward the light
//!   (along its ray to the light's centre, or against the sun's direction;
//!   θ the angle between the normal and that ray, tan θ capped at 8): a
//!   texel of the surface itself sits up to half a texel times the slope
//!   nearer the light than the point.
//!
//! The light behind the point's tangent plane is hidden by the surface
//! itself, which the biases remove from the maps: tangent_plane.rs bounds
//! the visibility by the part of the light in front of it.
//!
//! Too little leaves acne on lit surfaces; too much lets light leak where
//! an occluder touches a receiver (`docs/benchmarks/bias.md` measures both).

use crate::error::Result;
use crate::geom::light::MapGrid;
use crate::geom::light_space::LightSpace;
use crate::methods::{Input, LightPoint, Method, ShadowInputs};
pub(crate) use crate::pipeline::Stopwatch;
use crate::raster::Prepared;
use glam::DVec3;
use rayon::prelude::*;

/// The biases of the map methods, in texels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bias {
    pub normal_offset: f64,
    pub depth_bias: f64,
}

/// The map methods' light-view maps of an image.
#[derive(Debug, Clone)]
pub struct EyeMaps {
    pub grid: MapGrid,
    /// Front first, back last, in the user's depth (planar from the light,
    /// or orthographic from the sun's depth origin).
    pub layers: Vec<Vec<f32>>,
}

/// The largest slope the depth bias scales with (about 83 degrees).
const MAX_SLOPE: f64 = 8.0;

/// A texel's world size at a point of kernel depth `z` on `grid`.
fn texel_world(space: &LightSpace, grid: &MapGrid, z_world: f64) -> f64 {
    // The coarser of the texel's two sides, in tangent units.
    let t = (2.0 * grid.tx / grid.width as f64).max(2.0 * grid.ty / grid.height as f64);
    match space {
        LightSpace::Rect(_) => t * z_world,
        LightSpace::Sun(s) => t * s.lateral_scale(),
    }
}

/// The point moved by the biases, in world space.
fn biased(space: &LightSpace, p: DVec3, n: DVec3, texel: f64, bias: &Bias) -> DVec3 {
    let toward = match space {
        LightSpace::Rect(l) => (l.center - p).normalize_or_zero(),
        LightSpace::Sun(s) => -s.light.n,
    };
    // Slope-scaled: a surface at angle θ to the light rises tan θ per
    // texel across it (capped where it turns edge-on).
    let c = n.dot(toward).abs().max(1e-3);
    let tan = ((1.0 - c * c).max(0.0).sqrt() / c).min(MAX_SLOPE);
    let q = p + bias.normal_offset * texel * n;
    q + (1.0 + tan) * bias.depth_bias * texel * toward
}

/// What the map methods need of the scene: its triangles in kernel light
/// space (unit-scaled) as one indexed mesh.
pub struct LightTriangles {
    pub verts: Vec<DVec3>,
    pub faces: Vec<[u32; 3]>,
}

/// The occluder layers of every mesh on `grid` (kernel depths, unit-scaled),
/// front first, the peeled ones, back last.
pub fn occluder_layers(grid: &MapGrid, tris: &LightTriangles, passes: u32) -> Vec<Vec<f32>> {
    let near = crate::pipeline::near_plane(&tris.verts);
    let prepared = Prepared::new(grid, &tris.verts, &tris.faces, near);
    let o = prepared.nearest_farthest(passes >= 2);
    let mut layers = vec![o.nearest];
    for k in 0..passes.saturating_sub(2) as usize {
        let next = prepared.peel(&layers[k]);
        layers.push(next);
    }
    if let Some(b) = o.farthest {
        layers.push(b);
    }
    layers
}

/// The points (world, with their camera-facing `normals`) moved by the
/// biases, in kernel light space (unit-scaled); `None` for a point the
/// biases move to or behind the light's plane.
pub fn biased_points(
    space: &LightSpace,
    unit: f64,
    grid: &MapGrid,
    points: &[[f64; 3]],
    normals: &[[f32; 3]],
    bias: &Bias,
) -> Vec<Option<LightPoint>> {
    points
        .par_iter()
        .zip(normals)
        .map(|(p, n)| {
            let p = DVec3::from_array(*p);
            let n = glam::Vec3::from_array(*n).as_dvec3();
            let z = space.to_light(p).z;
            let texel = texel_world(space, grid, z);
            let q = space.to_light(biased(space, p, n, texel, bias)) / unit;
            (q.z > 0.0).then(|| LightPoint {
                x: (q.x / q.z) as f32,
                y: (q.y / q.z) as f32,
                z: q.z as f32,
            })
        })
        .collect()
}

/// Rasterizes the occluder layers on `grid` and shades `points` (world,
/// with their camera-facing `normals`). Returns the visibility per point and
/// the maps.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade(
    space: &LightSpace,
    unit: f64,
    light_size: [f64; 2],
    tris: &LightTriangles,
    grid: MapGrid,
    passes: u32,
    method: Method,
    points: &[[f64; 3]],
    normals: &[[f32; 3]],
    bias: &Bias,
    sw: &mut Stopwatch,
) -> Result<(Vec<f32>, EyeMaps)> {
    let mut layers = occluder_layers(&grid, tris, passes);
    sw.lap("raster_occluders");
    let lp = biased_points(space, unit, &grid, points, normals, bias);
    sw.lap("bias");
    let inputs = ShadowInputs {
        grid,
        occluder_grid: grid,
        light_size,
        receiver: &[],
        occluder_layers: layers.iter().map(|l| l.as_slice()).collect(),
        occluder_triangles: None,
    };
    debug_assert!(method.reads_input(Input::OccluderLayers));
    let mut v = crate::pipeline::shade_points(method, &inputs, &shaded_points(&lp));
    sw.lap("shadow");
    finish(&mut v, &lp, space, unit, light_size, points, normals);
    sw.lap("tangent_plane");
    for l in layers.iter_mut() {
        l.par_iter_mut()
            .for_each(|z| *z = user_depth(space, unit, *z));
    }
    Ok((v, EyeMaps { grid, layers }))
}

/// The points the kernels shade: one the biases moved behind the light
/// (`None`) as no receiver (`finish` then gives it 0). Both backends.
pub(crate) fn shaded_points(lp: &[Option<LightPoint>]) -> Vec<LightPoint> {
    let empty = LightPoint {
        x: 0.0,
        y: 0.0,
        z: f32::INFINITY,
    };
    lp.iter().map(|p| p.unwrap_or(empty)).collect()
}

/// What both backends do with the kernel's visibility `v` of `lp`: 0 where
/// the biases left no point, then the tangent-plane bound.
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish(
    v: &mut [f32],
    lp: &[Option<LightPoint>],
    space: &LightSpace,
    unit: f64,
    light_size: [f64; 2],
    points: &[[f64; 3]],
    normals: &[[f32; 3]],
) {
    for (v, p) in v.iter_mut().zip(lp) {
        if p.is_none() {
            *v = 0.0;
        }
    }
    super::tangent_plane::bound(v, space, unit, light_size, points, normals);
}

/// A layer depth of the kernels (in the depth unit `unit`) as the user's
/// maps hold it.
#[inline]
pub(crate) fn user_depth(space: &LightSpace, unit: f64, z: f32) -> f32 {
    space.user_depth(z * unit as f32)
}
