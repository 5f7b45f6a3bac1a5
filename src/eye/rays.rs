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

use crate::geom::light_space::LightSpace;
use crate::methods::exact::{sample_grid, stratified, Bvh};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Mitsuba's `math::RayEpsilon<float>`: 1500 float32 epsilons.
pub const RAY_EPSILON: f64 = 1500.0 / (1u64 << 24) as f64;

/// Visibility at surface points `points` (world) with normals `normals`,
/// every triangle of `triangles` (kernel light space, in the depth unit
/// `unit`) blocking. A rectangle emits on its n side only: points at or
/// behind its plane get 0.
pub fn visibility(
    space: &LightSpace,
    unit: f64,
    light_size: [f64; 2],
    triangles: Vec<[Vec3; 3]>,
    points: &[[f64; 3]],
    normals: &[[f32; 3]],
    samples: u32,
) -> Vec<f32> {
    let bvh = Bvh::build(triangles);
    let grid = sample_grid(samples, light_size);
    let size = light_size.map(|s| s as f32);
    let to_kernel = |p: DVec3| (space.to_light(p) / unit).as_vec3();
    points
        .par_iter()
        .zip(normals)
        .enumerate()
        .with_min_len(64)
        .map(|(k, (p, n))| {
            let p = DVec3::from_array(*p);
            let n = Vec3::from_array(*n).as_dvec3();
            // side(x, y) = a0 + x au + y av: which side of the surface the
            // light point (x, y) (kernel units) lies on.
            let (a0, au, av) = match space {
                LightSpace::Rect(l) => {
                    if (p - l.center).dot(l.n) <= 0.0 {
                        return 0.0;
                    }
                    (n.dot(l.center - p) / unit, n.dot(l.u), n.dot(l.v))
                }
                LightSpace::Sun(s) => (-n.dot(s.light.n), -n.dot(s.light.u), -n.dot(s.light.v)),
            };
            let mag = (1.0 + p.abs().max_element()) * RAY_EPSILON;
            let above = to_kernel(p + mag * n);
            let below = to_kernel(p - mag * n);
            let (a0, au, av) = (a0 as f32, au as f32, av as f32);
            stratified(&bvh, k as u64, grid, size, |x, y| {
                let o = if a0 + x * au + y * av >= 0.0 {
                    above
                } else {
                    below
                };
                (o, Vec3::new(x, y, 0.0) - o, 0.0)
            })
        })
        .collect()
}
