//! `exact` in the eye view: stratified shadow rays from every pixel's
//! surface point through a BVH of every mesh (the point's own included).
//!
//! A ray must not hit the surface it leaves by round-off. As Mitsuba's
//! `spawn_ray_to` does, its origin moves off the surface along the
//! geometric normal by `(1 + max|p|) * 1500 * 2^-24` (world units), to the
//! side the ray leaves by: a ray toward the light's side of the surface
//! starts on that side, one through the surface (the far side of a closed
//! mesh, lit from behind) starts behind it and is blocked by it. The
//! offsets are computed in world space (f64) and both candidate origins
//! moved to the kernels' light space (`geom/light_space.rs`), where the rays
//! are traced exactly as the light-view `exact` traces them.

use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::methods::engine::{visibilities_weighted, Engine};
use crate::methods::exact::Bvh;
use crate::methods::probe::probed_visibilities_weighted;
pub use crate::trace::ray_start::RayStart;
use crate::trace::shadow_rays::{tile_order, Jitter, Sampling};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Mitsuba's `math::RayEpsilon<float>`: 1500 float32 epsilons.
pub const RAY_EPSILON: f64 = 1500.0 / (1u64 << 24) as f64;

/// Which side of the tangent plane at `p` (normal `n`, world) each light
/// point lies on, as `[a0, a1, a2]` with `a0 + a1 x + a2 y >= 0` in front
/// for the light point (x, y) in kernel units (unit-scaled); `None` at or
/// behind a rectangle's plane (it emits on its n side only).
pub fn plane_side(space: &LightSpace, unit: f64, p: DVec3, n: DVec3) -> Option<[f64; 3]> {
    match space {
        LightSpace::Area(l) => {
            if (p - l.center).dot(l.n) <= 0.0 {
                return None;
            }
            Some([n.dot(l.center - p) / unit, n.dot(l.u), n.dot(l.v)])
        }
        LightSpace::Sun(s) => Some([-n.dot(s.light.n), -n.dot(s.light.u), -n.dot(s.light.v)]),
    }
}

/// The ray starts of surface points `points` (world) with normals
/// `normals` (facing the camera), in kernel light space in the depth unit
/// `unit`; `None` at or behind a rectangle's plane.
pub fn ray_starts(
    space: &LightSpace,
    unit: f64,
    points: &[[f64; 3]],
    normals: &[[f32; 3]],
) -> Vec<Option<RayStart>> {
    let to_kernel = |p: DVec3| (space.to_light(p) / unit).as_vec3();
    points
        .par_iter()
        .zip(normals)
        .map(|(p, n)| {
            let p = DVec3::from_array(*p);
            let n = Vec3::from_array(*n).as_dvec3();
            let side = plane_side(space, unit, p, n)?;
            let mag = (1.0 + p.abs().max_element()) * RAY_EPSILON;
            Some(RayStart {
                above: to_kernel(p + mag * n),
                below: to_kernel(p - mag * n),
                side: side.map(|a| a as f32),
            })
        })
        .collect()
}

/// Visibility at ray starts `starts`, every triangle of `triangles`
/// (kernel light space, unit-scaled) blocking; 0 for `None`. Start k's
/// jitter key is `key(k)`: its pixel's flat index in the image (its
/// texel's in a map), never its rank among the starts, so that a pixel's
/// samples do not depend on which other pixels see a surface
/// (`shadow_rays::visibilities`; eye_rays.wgsl reads the same key).
/// `order` (a permutation of the indices of `starts`) is the order to
/// trace them in: neighbours next to each other (`tiled`), so that packets
/// are coherent. With a `probe` (its light samples, and the image of the
/// keys), only the starts a first pass is unsure of trace `samples`
/// (`methods/probe.rs`).
pub fn visibility(
    light_shape: LightShape,
    triangles: Vec<[Vec3; 3]>,
    starts: &[Option<RayStart>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    sampled: (u32, Engine),
    probe: Option<Probe>,
) -> Vec<f32> {
    visibility_in(
        &Bvh::build(triangles),
        light_shape,
        starts,
        key,
        order,
        sampled,
        probe,
    )
}

/// A first pass of `samples` light samples at every start, whose keys are
/// pixels (texels) of an image of `size` (width, height): `methods/probe.rs`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Probe {
    pub samples: u32,
    pub size: (usize, usize),
}

/// `visibility` through a BVH already built (the error estimate traces
/// several batches through one).
pub fn visibility_in(
    bvh: &Bvh,
    light_shape: LightShape,
    starts: &[Option<RayStart>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    sampled: (u32, Engine),
    probe: Option<Probe>,
) -> Vec<f32> {
    visibility_weighted(bvh, light_shape, starts, key, order, sampled, probe)
        .into_iter()
        .map(|[v, _]| v)
        .collect()
}

/// `visibility_in` with each point's weighted visibility beside it: the
/// share of the light's irradiance its clear samples carry
/// (`RayStart::weight`, `shadow_rays::visibilities_weighted`), of a planar
/// light; a sun's samples (directions) weigh alike. `sampled`: the
/// samples and the engine that decides them (`methods/engine.rs`; a probe
/// traces rays).
pub fn visibility_weighted(
    bvh: &Bvh,
    light_shape: LightShape,
    starts: &[Option<RayStart>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    (samples, engine): (u32, Engine),
    probe: Option<Probe>,
) -> Vec<[f32; 2]> {
    let sampling = |n, jitter| Sampling {
        light: light_shape.samples(n),
        t0: 0.0,
        jitter,
    };
    let fine = sampling(samples, Jitter::Shared);
    match probe {
        Some(p) => {
            let coarse = sampling(p.samples, Jitter::PerReceiver);
            probed_visibilities_weighted(
                bvh,
                starts,
                key,
                order,
                (&fine, engine),
                &coarse,
                0.0,
                p.size,
            )
        }
        None => visibilities_weighted(engine, bvh, starts, key, order, &fine, 0.0),
    }
}

/// The order of `pixels` (flat indices into an image `width` wide, each
/// once) in 4 x 2 tiles (`shadow_rays::tile_order`): the indices into `pixels`.
pub fn tiled(pixels: &[usize], width: usize, height: usize) -> Vec<usize> {
    let mut at = vec![usize::MAX; width * height];
    for (k, &p) in pixels.iter().enumerate() {
        at[p] = k;
    }
    tile_order(width, height)
        .into_iter()
        .map(|p| at[p])
        .filter(|&k| k != usize::MAX)
        .collect()
}
