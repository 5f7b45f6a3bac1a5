//! The light view's error estimate (`soft_shadow_map(...,
//! estimate_error=True)`, always on for `Auto` with a target): exact rays
//! at a random subset of the receiver texels, compared with the result
//! there (the statistics: `crate::error_estimate`).
//!
//! The rays are light-view `exact`'s own: the same receiver origins (a
//! texel's point on its receiver, or a self-shadowing scene's offset ray
//! start), the same start of the segments (`t0`), and each texel's samples
//! keyed by its index in the map, as `exact` keys them; so `exact` checked
//! with its own sample count has estimate 0, and with more samples the
//! difference is its sampling error alone.
//!
//! The texels are drawn as the eye view draws pixels (`eye/estimate.rs`,
//! whose constants this shares but the maps' reference samples,
//! `REFERENCE_SAMPLES` below): units of a 4 x 2 tile in two strata (the
//! result's shadow gets three quarters of the draw), traced in batches
//! while the estimate has spent less than `SHARE` of the call
//! (`Draw::Timed`), or `PLANNED_UNITS` units whatever the time
//! (`Draw::Fixed`). The rays go through one BVH of every occluder
//! triangle, built as `exact` builds it, before the first batch: its build
//! is outside the timed budget (the eye view's per-batch culling is not
//! done here; the light view's scenes measured so far are small: the
//! fence's whole estimate took 8 ms).

use std::time::Instant;

use glam::Vec3;

use crate::error_estimate::{
    add_batch, finish, strata_order, Draw, ErrorEstimate, Stratum, SHADOW_THRESHOLD,
};
use crate::eye::estimate::{BATCH, MAX_UNITS, PLANNED_UNITS, SHADOW_SHARE, SHARE, UNIT};
use crate::frame::{light_space_triangles, FramedScene};
use crate::geom::light_shape::LightShape;
use crate::methods::config::MAX_SAMPLES;
use crate::methods::exact::{receiver_points, Bvh, RAY_EPS};
use crate::methods::Method;
use crate::trace::shadow_rays::{tile_order, visibilities, Jitter, RayOrigin, Sampling};

/// Light samples of the exact rays at each drawn texel, for a result of
/// the map methods: four times the eye view's `REFERENCE_SAMPLES`. At 256
/// the reference's own error is about the targets it checks: on the fence
/// at 256² (against 4096 samples) 0.0081 at 256 samples, 0.0031 at 1024;
/// `Bitmask(samples=1024)` there was 0.0029, so a 256-sample estimate
/// (0.0087) measured the reference's noise. A light-view texel is cheap to
/// trace: 1024 texels at 1024 samples took 13 ms on the fence.
pub const REFERENCE_SAMPLES: u32 = 4 * crate::eye::estimate::REFERENCE_SAMPLES;

/// The exact rays' light samples for a result of `method`: a ray-traced
/// kernel (`exact`) against four times its own samples (its sampling error), the map
/// methods against `REFERENCE_SAMPLES`.
pub fn reference_samples(method: Method) -> u32 {
    match method.rays() {
        Some((samples, ..)) => samples.saturating_mul(4).min(MAX_SAMPLES),
        None => REFERENCE_SAMPLES,
    }
}

/// The estimate of a mesh call's `visibility`, its receiver map `receiver`
/// (kernel unit) on the framed scene `f`'s grid, the occluders' faces
/// `faces`: rays with `samples` light samples from each texel's receiver
/// point, as `exact`'s.
pub fn of_meshes(
    f: &FramedScene,
    faces: &[[u32; 3]],
    (receiver, visibility): (&[f32], &[f32]),
    samples: u32,
    drawn: (Draw, f64),
) -> ErrorEstimate {
    let g = &f.grid;
    let origins = receiver_points(g, receiver);
    let at = Receivers {
        size: (g.width, g.height),
        origins: &origins,
        t0: RAY_EPS,
    };
    let triangles = light_space_triangles(&f.occ_ls, faces);
    estimate(&at, f.light_shape, triangles, visibility, samples, drawn)
}

/// What the exact rays start from: per texel of a `width` x `height` map
/// (row-major), its ray origin or None (no receiver there: not drawn), and
/// where along the segment to the light the rays start (`t0`).
pub(crate) struct Receivers<'a, R> {
    pub size: (usize, usize),
    pub origins: &'a [Option<R>],
    pub t0: f32,
}

/// The estimate of `visibility` (per texel) against exact rays with
/// `samples` light samples of `light_shape` through `triangles` (kernel
/// light space), drawn as `how` says, the call having taken `spent`
/// seconds so far.
pub(crate) fn estimate<R: RayOrigin + Copy>(
    at: &Receivers<R>,
    light_shape: LightShape,
    triangles: Vec<[Vec3; 3]>,
    visibility: &[f32],
    samples: u32,
    (how, spent): (Draw, f64),
) -> ErrorEstimate {
    let t0 = Instant::now();
    let (budget, most) = match how {
        Draw::Timed => (SHARE * spent, MAX_UNITS),
        Draw::Fixed => (f64::INFINITY, PLANNED_UNITS),
    };
    // Units: runs of UNIT receiver texels in 4 x 2 tile order (mostly
    // whole tiles), in the result's shadow when any of their texels is.
    let (width, height) = at.size;
    let texels: Vec<usize> = tile_order(width, height)
        .into_iter()
        .filter(|&k| at.origins[k].is_some())
        .collect();
    let units: Vec<&[usize]> = texels.chunks(UNIT).collect();
    let (shadow, lit): (Vec<usize>, Vec<usize>) = (0..units.len()).partition(|&u| {
        units[u]
            .iter()
            .any(|&k| 1.0 - visibility[k] > SHADOW_THRESHOLD)
    });
    let order = strata_order((&shadow, &lit), units.len().min(most), SHADOW_SHARE);
    let mut strata = [Stratum::default(), Stratum::default()];
    strata[0].population = shadow.len();
    strata[1].population = lit.len();
    let mut traced = 0;
    if !order.is_empty() {
        let bvh = Bvh::build(triangles);
        // exact's own rays (its pattern, shared by every texel).
        let s = Sampling {
            light: light_shape.samples(samples),
            t0: at.t0,
            jitter: Jitter::Shared,
        };
        for batch in order.chunks(BATCH) {
            if traced > 0 && t0.elapsed().as_secs_f64() > budget {
                break;
            }
            let drawn: Vec<usize> = batch
                .iter()
                .flat_map(|&(_, u)| units[u].iter().copied())
                .collect();
            let origins: Vec<Option<R>> = drawn.iter().map(|&k| at.origins[k]).collect();
            let identity: Vec<usize> = (0..drawn.len()).collect();
            // Keyed by the texel, as `exact` keys its samples.
            let exact = visibilities(&bvh, &origins, |j| drawn[j] as u64, &identity, &s, 1.0);
            add_batch(&mut strata, batch, &units, visibility, &exact);
            traced += drawn.len();
        }
    }
    finish(&strata, traced, samples, t0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;
    use crate::frame::{frame_scene, MapSettings};
    use crate::geom::light::AreaLight;
    use crate::geom::light_space::Light;
    use crate::geom::mesh::MeshRef;
    use crate::methods::{ExactConfig, MethodConfig};
    use crate::raster::rasterize;
    use crate::timing::Stopwatch;

    /// A plate of slats over a floor under a 1 x 1 light: `exact` with n
    /// samples, checked against rays of n samples, has estimate 0 (the
    /// same rays); against 4n, a small error; a fixed draw the same twice.
    #[test]
    fn exact_checked_with_its_own_samples_has_estimate_zero() {
        let quad = |x: f64, y: f64, w: f64, h: f64| {
            vec![[x - w, y, -h], [x + w, y, -h], [x + w, y, h], [x - w, y, h]]
        };
        let faces = vec![[0u32, 2, 1], [0, 3, 2]];
        let floor = quad(0.0, 0.0, 3.0, 3.0);
        let (mut slats, mut slat_faces) = (vec![], vec![]);
        for i in 0..5 {
            let base = slats.len() as u32;
            slats.extend(quad(-1.0 + 0.5 * i as f64, 1.0, 0.1, 1.0));
            slat_faces.extend(faces.iter().map(|f| f.map(|v| v + base)));
        }
        let (occ, rec) = (
            MeshRef {
                vertices: &slats,
                faces: &slat_faces,
            },
            MeshRef {
                vertices: &floor,
                faces: &faces,
            },
        );
        let light = Light::Area(
            AreaLight::rect(
                [0.2, 4.0, 0.1],
                [0.0, -1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0],
            )
            .unwrap(),
        );
        let space = light
            .space_for(floor.iter().map(|p| glam::DVec3::from_array(*p)))
            .unwrap();
        let n = 16;
        let cfg = MethodConfig::Exact(ExactConfig::of(n));
        let mut s = MapSettings::new(96, 64, None, &cfg);
        let map = crate::pipeline::from_meshes(occ, rec, &space, &s, Backend::Cpu).unwrap();
        assert!(map.estimate.is_none());
        let f = frame_scene(&occ, &rec, &space, &s, &mut Stopwatch::new()).unwrap();
        let receiver = rasterize(&f.grid, &f.rec_ls, rec.faces, f.near, false).nearest;
        let check = |samples| {
            of_meshes(
                &f,
                occ.faces,
                (&receiver, &map.visibility),
                samples,
                (Draw::Fixed, 0.0),
            )
        };
        let same = check(n);
        assert_eq!(same.traced, PLANNED_UNITS * UNIT);
        assert!(same.shadowed > 100, "{same:?}");
        assert_eq!((same.error, same.low, same.high), (0.0, 0.0, 0.0));
        let more = check(4 * n);
        assert!(more.error > 0.0 && more.high < 0.1, "{more:?}");
        let again = check(4 * n);
        assert_eq!(
            (more.error, more.low, more.high),
            (again.error, again.low, again.high)
        );
        // The pipeline's own: four times exact's samples.
        s.estimate = Some(Draw::Fixed);
        let run = crate::pipeline::from_meshes(occ, rec, &space, &s, Backend::Cpu).unwrap();
        let e = run.estimate.unwrap();
        assert_eq!(
            (e.samples, e.error, e.traced),
            (4 * n, more.error, more.traced)
        );
        assert!(run.timings.iter().any(|t| t.0 == "estimate"));
    }
}
