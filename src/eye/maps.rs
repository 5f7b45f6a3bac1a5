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

use super::rays::ray_starts;
use super::tangent_plane;
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::geom::plane_gradient::plane_gradient;
use crate::methods::{EyePoints, Input, LightPoint, Method, ShadowInputs};
use crate::raster::Prepared;
pub(crate) use crate::timing::Stopwatch;
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

/// The default biases of the map methods (texels), measured by
/// `benchmarks/bench_bias.py` (docs/benchmarks/bias.md) on the four
/// eye-view scenes: without either bias up to 55% of the lit pixels shadow
/// themselves; a quarter texel of normal offset and half a texel of depth
/// bias bring that to 0.3% (the map's penumbra edges), and every further
/// texel of either lets more light leak into the shadows.
pub const DEFAULT_BIAS: Bias = Bias {
    normal_offset: 0.25,
    depth_bias: 0.5,
};
/// The largest bias accepted, in texels.
pub const MAX_BIAS: f64 = 64.0;

impl Bias {
    /// Checks user biases (finite, in [0, MAX_BIAS]); `None` keeps a default.
    pub fn new(normal_offset: Option<f64>, depth_bias: Option<f64>) -> Result<Bias> {
        let check = |arg: &str, v: Option<f64>, d: f64| match v {
            None => Ok(d),
            Some(v) if v.is_finite() && (0.0..=MAX_BIAS).contains(&v) => Ok(v),
            Some(v) => Err(Error::invalid(
                arg,
                format!("must be a number of texels in [0, {MAX_BIAS}], got {v}"),
            )),
        };
        Ok(Bias {
            normal_offset: check("normal_offset", normal_offset, DEFAULT_BIAS.normal_offset)?,
            depth_bias: check("depth_bias", depth_bias, DEFAULT_BIAS.depth_bias)?,
        })
    }
}

/// The largest slope the depth bias scales with (about 83 degrees).
const MAX_SLOPE: f64 = 8.0;

/// A texel's world size at a point of kernel depth `z` on `grid`.
fn texel_world(space: &LightSpace, grid: &MapGrid, z_world: f64) -> f64 {
    // The coarser of the texel's two sides, in tangent units.
    let t = (2.0 * grid.tx / grid.width as f64).max(2.0 * grid.ty / grid.height as f64);
    match space {
        LightSpace::Area(_) => t * z_world,
        LightSpace::Sun(s) => t * s.lateral_scale(),
    }
}

/// The point moved by the biases, in world space.
fn biased(space: &LightSpace, p: DVec3, n: DVec3, texel: f64, bias: &Bias) -> DVec3 {
    let toward = match space {
        LightSpace::Area(l) => (l.center - p).normalize_or_zero(),
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
pub struct LightTriangles<'a> {
    pub verts: Vec<DVec3>,
    pub faces: &'a [[u32; 3]],
}

/// The occluder layers of every mesh on `grid` (kernel depths, unit-scaled),
/// front first, the peeled ones, back last.
pub fn occluder_layers(grid: &MapGrid, tris: &LightTriangles, passes: u32) -> Vec<Vec<f32>> {
    let near = crate::raster::near_plane(&tris.verts);
    let prepared = Prepared::new(grid, &tris.verts, tris.faces, near);
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

/// The points the kernels shade, and the bound their visibility is cut to.
pub struct ShadingPoints {
    /// The points moved by the biases, kernel light space (unit-scaled);
    /// an empty point (z = inf, which no kernel shades) where there is
    /// nothing to shade: a bound of 0.
    pub points: Vec<LightPoint>,
    /// The fraction of the light in front of each point's tangent plane
    /// (tangent_plane.rs); 0 where the biases move the point to or behind
    /// the light's plane, or it lies at or behind a rectangle's plane.
    pub bound: Vec<f32>,
    /// Each point's tangent plane on the grid, (∂(1/z)/∂px, ∂(1/z)/∂py) in
    /// kernel units (`geom::plane_gradient::Plane`, for the taps of PCSS and Smoothies), where asked
    /// for; else empty.
    pub planes: Vec<[f32; 2]>,
}

/// The point no kernel shades (it has no depth in front of the light).
pub(crate) const EMPTY_POINT: LightPoint = LightPoint {
    x: 0.0,
    y: 0.0,
    z: f32::INFINITY,
};

/// A light-space point (unit-scaled) as the kernels read it: its tangents
/// and depth (`q.z > 0`, in front of the light).
pub(crate) fn kernel_point(q: DVec3) -> LightPoint {
    let inv_z = 1.0 / q.z;
    LightPoint {
        x: (q.x * inv_z) as f32,
        y: (q.y * inv_z) as f32,
        z: q.z as f32,
    }
}

/// The points (world, with their camera-facing `normals`, and `pts_ls`
/// their kernel light-space images before unit scaling) moved by the
/// biases, and their tangent-plane bounds, in one pass. A point whose bound
/// is 0 (the far side of a closed mesh, facing away from the whole light)
/// is not shaded: its visibility is 0 whatever the maps say. Both backends.
#[allow(clippy::too_many_arguments)]
pub fn shading_points(
    space: &LightSpace,
    unit: f64,
    light_shape: LightShape,
    grid: &MapGrid,
    points: &[[f64; 3]],
    pts_ls: &[DVec3],
    normals: &[[f32; 3]],
    bias: &Bias,
    planes: bool,
) -> ShadingPoints {
    let inv_unit = 1.0 / unit;
    let mut out = ShadingPoints {
        points: vec![EMPTY_POINT; points.len()],
        bound: vec![0.0; points.len()],
        planes: vec![[0.0; 2]; if planes { points.len() } else { 0 }],
    };
    // A world point on the grid: (px, py, 1/z), z its kernel depth.
    let on_grid = |w: DVec3| {
        let q = space.to_light(w) * inv_unit;
        (q.z > 0.0).then(|| {
            let (px, py) = grid.to_pixel(q.x / q.z, q.y / q.z);
            DVec3::new(px, py, 1.0 / q.z)
        })
    };
    let mut plane_slots: Vec<Option<&mut [f32; 2]>> = if planes {
        out.planes.iter_mut().map(Some).collect()
    } else {
        (0..points.len()).map(|_| None).collect()
    };
    out.points
        .par_iter_mut()
        .zip(out.bound.par_iter_mut())
        .zip(plane_slots.par_iter_mut())
        .zip(points.par_iter().zip(pts_ls).zip(normals))
        .with_min_len(1024)
        .for_each(|(((lp, b), slot), ((p, q), n))| {
            let p = DVec3::from_array(*p);
            let n = glam::Vec3::from_array(*n).as_dvec3();
            let front = tangent_plane::front_of(space, unit, light_shape, p, n);
            if front <= 0.0 {
                return;
            }
            let texel = texel_world(space, grid, q.z);
            let moved = biased(space, p, n, texel, bias);
            let q = space.to_light(moved) * inv_unit;
            if q.z > 0.0 {
                *lp = kernel_point(q);
                *b = front as f32;
                // The plane through the biased point: 1/z is linear on the
                // grid over it, so a texel's step is exact at any size.
                if let Some(slot) = slot {
                    if let Some(g) = plane_gradient(on_grid, moved, n, texel) {
                        **slot = g.map(|v| v as f32);
                    }
                }
            }
        });
    drop(plane_slots);
    out
}

/// What the map methods give for the visible points: each one's visibility,
/// beside it its weighted visibility where the method weighs its samples
/// (under an area light the bitmask's and the SSM's,
/// `ShadowMethod::visibility_eye`, and PCSS's filter cells,
/// `Pcss::weighted_on_planes`),
/// and the maps.
pub struct MapShading {
    pub visibility: Vec<f32>,
    pub weighted: Option<Vec<f32>>,
    pub maps: EyeMaps,
}

impl MapShading {
    /// A method's that does not weigh its samples.
    pub fn unweighted(visibility: Vec<f32>, maps: EyeMaps) -> MapShading {
        MapShading {
            visibility,
            weighted: None,
            maps,
        }
    }
}

/// Rasterizes the occluder layers on `grid` and shades `points` (world,
/// with their camera-facing `normals`); with `weigh`, under an area light,
/// weighs each point's samples too where the method has them
/// (`MapShading::weighted`: what the eye view's shaded image reads).
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade(
    space: &LightSpace,
    unit: f64,
    light_shape: LightShape,
    tris: &LightTriangles,
    grid: MapGrid,
    passes: u32,
    method: Method,
    points: &[[f64; 3]],
    pts_ls: &[DVec3],
    normals: &[[f32; 3]],
    bias: &Bias,
    arg: &str,
    weigh: bool,
    sw: &mut Stopwatch,
) -> Result<MapShading> {
    let mut layers = occluder_layers(&grid, tris, passes);
    sw.lap("raster_occluders");
    let sp = shading_points(
        space,
        unit,
        light_shape,
        &grid,
        points,
        pts_ls,
        normals,
        bias,
        method.tests_planes(),
    );
    // The weights are the unbiased surface point's, under an area light
    // (the sun's shading has no weights: shading.rs).
    let receivers = (weigh && matches!(space, LightSpace::Area(_)))
        .then(|| ray_starts(space, unit, points, normals));
    sw.lap("bias");
    let inputs = ShadowInputs {
        grid,
        occluder_grid: grid,
        light_shape,
        receiver: &[],
        occluder_layers: layers.iter().map(|l| l.as_slice()).collect(),
        occluder_triangles: None,
    };
    debug_assert!(method.reads_input(Input::OccluderLayers));
    let eye = EyePoints {
        points: &sp.points,
        planes: &sp.planes,
        starts: receivers.as_deref(),
        verts: &tris.verts,
        faces: tris.faces,
    };
    let shade = || crate::methods::shade_eye(method, &inputs, &eye);
    let (mut v, mut weighted) =
        crate::methods::bounded(method, &inputs, Some(&sp.points), arg, shade)?;
    sw.lap("shadow");
    finish(&mut v, &sp.bound);
    if let Some(w) = &mut weighted {
        finish_weighted(w, &sp.bound);
    }
    for l in layers.iter_mut() {
        l.par_iter_mut()
            .for_each(|z| *z = user_depth(space, unit, *z));
    }
    Ok(MapShading {
        visibility: v,
        weighted,
        maps: EyeMaps { grid, layers },
    })
}

/// What both backends do with the kernel's weighted visibility `w`: 0 at a
/// point not shaded (bound 0: it sees none of the light). The weights
/// themselves leave out the part behind its tangent plane, so no cut.
pub(crate) fn finish_weighted(w: &mut [f32], bound: &[f32]) {
    w.par_iter_mut().zip(bound).for_each(|(w, b)| {
        if *b <= 0.0 {
            *w = 0.0;
        }
    });
}

/// What both backends do with the kernel's visibility `v`: each point's
/// cut to its bound (`ShadingPoints::bound`).
pub(crate) fn finish(v: &mut [f32], bound: &[f32]) {
    v.par_iter_mut().zip(bound).for_each(|(v, b)| {
        // (+ 0.0 turns a -0.0 from the min into 0.)
        *v = v.min(*b) + 0.0;
    });
}

/// A layer depth of the kernels (in the depth unit `unit`) as the user's
/// maps hold it.
#[inline]
pub(crate) fn user_depth(space: &LightSpace, unit: f64, z: f32) -> f32 {
    space.user_depth(z * unit as f32)
}
