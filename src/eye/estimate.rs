//! The eye view's error estimate (`estimate_error=True`, always on for
//! `Auto` with a target): exact stratified rays (`rays.rs`, the `exact`
//! method's own) at a random subset of the visible pixels, compared with
//! the result there (the statistics: `crate::error_estimate`).
//!
//! The pixels are drawn in units of a 4 x 2 tile (their rays go in one
//! coherent packet; single scattered pixels traced 7 times slower), in two
//! strata: the units in the result's shadow (visibility below 1 − 0.001),
//! where the error lives, get three quarters of the draw; the lit rest a
//! quarter (a shadow the result missed is found there). The units are
//! traced in batches of `BATCH`, while the estimate has spent less than
//! `SHARE` of the call so far (the first batch always), at most
//! `MAX_UNITS` (`Draw::Timed`); or `PLANNED_UNITS` of them whatever the
//! time (`Draw::Fixed`, for a plan checked against its estimate: it must
//! not depend on how fast the machine is).
//!
//! A batch's rays meet only the triangles in the shafts from its tiles to
//! the light (`in_shaft`, a box test), so each batch builds a small BVH of
//! those (`Bvh::build_fast`) instead of one of the whole scene, whose build
//! alone took 30–40% of a map method's call on 339 000 triangles. Once the
//! batches would together test more triangle-shaft pairs than a whole
//! scene's BVH costs to build, the rest is traced through one. The estimate
//! runs on the CPU for both backends.

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::framing::Framed;
use super::gbuffer::GBuffer;
use super::rays::{self, RayStart};
use super::sphere_rays::sphere_visibility;
use crate::error_estimate::{
    add_batch, finish, strata_order, Draw, ErrorEstimate, Stratum, SHADOW_THRESHOLD,
};
use crate::geom::sphere_light::SphereLight;
use crate::methods::engine::Engine;
use crate::methods::exact::Bvh;
use crate::trace::shadow_rays::RayOrigin;

/// Light samples of the exact rays at each drawn pixel, for a result of
/// the map methods: their stratified error (about 1/256 in a penumbra) is
/// well below the errors the estimate tells apart.
pub const REFERENCE_SAMPLES: u32 = 256;
/// Neighbouring pixels traced together (a 4 x 2 tile, one packet of rays).
pub const UNIT: usize = 8;
/// Units per batch (128 pixels); the first batch is traced whatever the
/// budget.
pub const BATCH: usize = 16;
/// The most units traced (16384 pixels).
pub const MAX_UNITS: usize = 2048;
/// The units a fixed draw traces (1024 pixels): a 95% interval about a
/// fifth of the estimate wide on the as-built scenes' shadows, at 7% of an
/// `exact` call's rays at 320x240 (its own four times the samples at 1024
/// of about 60 000 pixels).
pub const PLANNED_UNITS: usize = 128;
/// The estimate's share of the call's time: at most a ninth of the rest
/// (a tenth of the whole).
pub const SHARE: f64 = 1.0 / 9.0;
/// The share of the drawn units taken in the result's shadow.
pub const SHADOW_SHARE: f64 = 0.75;
/// Tiles culled (each tests every triangle's box once) that a whole-scene
/// BVH build is worth, at least: on `crowd` (339 000 triangles, 2 cores) a
/// Morton build took 144–163 ms and a whole first batch of 16 tiles
/// (culling, its BVH, its rays) 33 ms, so a build costs over 70 tiles'.
const TESTS_PER_BUILD: usize = 64;

/// The estimate of `visibility` (per visible point of `f`, in its order)
/// against exact rays with `samples` light samples through `triangles`
/// (kernel light space: every triangle that can shadow a point), the
/// image `width` x `height`, drawn as `how` says, the call having taken
/// `spent` seconds so far.
pub fn estimate(
    f: &Framed,
    size: (usize, usize),
    triangles: Vec<[Vec3; 3]>,
    visibility: &[f32],
    samples: u32,
    (how, spent): (Draw, f64),
) -> ErrorEstimate {
    estimate_with(
        f,
        size,
        Occluders::Triangles(triangles),
        visibility,
        samples,
        draw_limits(how, spent),
        true,
    )
}

/// `estimate`, its rays through `bvh` (`exact`'s own tree of the same
/// triangles: nothing to cull or build).
pub fn estimate_in(
    f: &Framed,
    size: (usize, usize),
    bvh: &Bvh,
    visibility: &[f32],
    samples: u32,
    (how, spent): (Draw, f64),
) -> ErrorEstimate {
    estimate_with(
        f,
        size,
        Occluders::Tree(bvh),
        visibility,
        samples,
        draw_limits(how, spent),
        true,
    )
}

/// The estimate of a sphere light's `visibility` (per point of `hits`,
/// flat indices into `g`) against the sphere's own rays
/// (`sphere_rays::sphere_visibility`, no probe) with `samples` samples over
/// each point's cap through `bvh` (`sphere_bvh`), drawn as `how` says, the
/// call having taken `spent` seconds so far. Each pixel's rays are keyed by
/// its place in the image, as the result's are.
pub fn estimate_sphere(
    (bvh, light): (&Bvh, &SphereLight),
    g: &GBuffer,
    hits: &[usize],
    visibility: &[f32],
    samples: u32,
    (how, spent): (Draw, f64),
) -> ErrorEstimate {
    let t0 = Instant::now();
    let (most, budget) = draw_limits(how, spent);
    let trace = |pixels: &[usize], _: &[usize], _: f64| {
        let at: Vec<usize> = pixels.iter().map(|&j| hits[j]).collect();
        sphere_visibility(bvh, light, g, &at, samples, None)
            .into_iter()
            .map(|[v, _]| v)
            .collect()
    };
    drawn(
        (hits, (g.width, g.height)),
        visibility,
        samples,
        (most, budget, t0),
        trace,
    )
}

/// What the estimate's rays meet: a tree already built, or the triangles,
/// culled to each batch's shafts (`in_shaft`) or built into one tree.
enum Occluders<'a> {
    Tree(&'a Bvh),
    Triangles(Vec<[Vec3; 3]>),
}

/// `estimate`; `cull` false traces every batch through one BVH of the
/// whole scene (the tests hold that culling changes no ray).
fn estimate_with(
    f: &Framed,
    size: (usize, usize),
    occluders: Occluders,
    visibility: &[f32],
    samples: u32,
    (most, budget): (usize, f64),
    cull: bool,
) -> ErrorEstimate {
    let t0 = Instant::now();
    let (given, triangles) = match occluders {
        Occluders::Tree(bvh) => (Some(bvh), vec![]),
        Occluders::Triangles(t) => (None, t),
    };
    let boxes: Vec<(Vec3, Vec3)> = triangles
        .par_iter()
        .map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])))
        .collect();
    let half = f.light_shape.half_extent().map(|h| h as f32);
    let (mut culled, mut cull_seconds) = (0usize, 0f64);
    let mut whole: Option<Bvh> =
        (!cull && given.is_none()).then(|| Bvh::build_fast(triangles.clone()));
    let trace = |pixels: &[usize], lens: &[usize], elapsed: f64| {
        // Culling tests every triangle once a tile: past TESTS_PER_BUILD
        // tiles one BVH of the scene costs less, if it fits the budget.
        if given.is_none() && whole.is_none() && culled >= TESTS_PER_BUILD {
            let build = cull_seconds / culled as f64 * TESTS_PER_BUILD as f64;
            if elapsed + build <= budget {
                whole = Some(Bvh::build_fast(triangles.clone()));
            }
        }
        let points: Vec<[f64; 3]> = pixels.iter().map(|&k| f.points[k]).collect();
        let normals: Vec<[f32; 3]> = pixels.iter().map(|&k| f.normals[k]).collect();
        let starts = rays::ray_starts(&f.space, f.unit, &points, &normals);
        // Each pixel's samples are keyed by its place in the image, as
        // `exact`'s are: with the same samples these rays are the full
        // image's.
        let key = |j: usize| f.hits[pixels[j]] as u64;
        let identity: Vec<usize> = (0..pixels.len()).collect();
        // The tree culled to this draw's shafts, where no tree is given.
        let culled_tree;
        let bvh = match given.or(whole.as_ref()) {
            Some(bvh) => bvh,
            None => {
                let t = Instant::now();
                culled += lens.len();
                let shafts = tile_boxes(&starts, lens.iter().copied());
                let kept: Vec<[Vec3; 3]> = triangles
                    .par_iter()
                    .zip(&boxes)
                    .filter(|(_, &(lo, hi))| {
                        shafts
                            .iter()
                            .any(|&(slo, shi)| in_shaft(lo, hi, slo, shi, half))
                    })
                    .map(|(t, _)| *t)
                    .collect();
                cull_seconds += t.elapsed().as_secs_f64();
                culled_tree = Bvh::build_fast(kept);
                &culled_tree
            }
        };
        rays::visibility_in(
            bvh,
            f.light_shape,
            &starts,
            key,
            &identity,
            (samples, Engine::Rays),
            None,
        )
    };
    drawn(
        (&f.hits, size),
        visibility,
        samples,
        (most, budget, t0),
        trace,
    )
}

/// The draw (module doc), free of what the rays meet: the visible points
/// `hits` (flat pixel indices of an image of `size`) in units of `UNIT`
/// in tile order, in two strata by the result's `visibility` (per point of
/// `hits`), drawn in batches of `BATCH` units while the time since `t0` is
/// within `budget` (the first batch always), at most `most` units. `trace`
/// takes a batch's points (indices into `hits`), its units' lengths and
/// the time spent, and returns the points' reference visibility with
/// `samples` light samples.
pub(crate) fn drawn(
    (hits, (width, height)): (&[usize], (usize, usize)),
    visibility: &[f32],
    samples: u32,
    (most, budget, t0): (usize, f64, Instant),
    mut trace: impl FnMut(&[usize], &[usize], f64) -> Vec<f32>,
) -> ErrorEstimate {
    // Units: runs of UNIT visible points in 4 x 2 tile order (mostly whole
    // tiles), in the result's shadow when any of their pixels is.
    let tiled = rays::tiled(hits, width, height);
    let units: Vec<&[usize]> = tiled.chunks(UNIT).collect();
    let (shadow, lit): (Vec<usize>, Vec<usize>) = (0..units.len()).partition(|&u| {
        units[u]
            .iter()
            .any(|&k| 1.0 - visibility[k] > SHADOW_THRESHOLD)
    });
    let total = units.len().min(most);
    let order = strata_order((&shadow, &lit), total, SHADOW_SHARE);
    let mut strata = [Stratum::default(), Stratum::default()];
    strata[0].population = shadow.len();
    strata[1].population = lit.len();
    let mut traced = 0;
    for batch in order.chunks(BATCH) {
        let elapsed = t0.elapsed().as_secs_f64();
        if traced > 0 && elapsed > budget {
            break;
        }
        let pixels: Vec<usize> = batch
            .iter()
            .flat_map(|&(_, u)| units[u].iter().copied())
            .collect();
        let lens: Vec<usize> = batch.iter().map(|&(_, u)| units[u].len()).collect();
        let exact = trace(&pixels, &lens, elapsed);
        add_batch(&mut strata, batch, &units, visibility, &exact);
        traced += pixels.len();
    }
    finish(&strata, traced, samples, t0)
}

/// The draw of a `Draw`: (units at most, the time budget) for a call that
/// has spent `spent` seconds.
pub(crate) fn draw_limits(how: Draw, spent: f64) -> (usize, f64) {
    match how {
        Draw::Timed => (MAX_UNITS, SHARE * spent),
        Draw::Fixed => (PLANNED_UNITS, f64::INFINITY),
    }
}

/// The box of each tile's ray origins (`starts` in runs of `lens`); an
/// empty box (lo > hi) for a tile with no start.
fn tile_boxes(starts: &[Option<RayStart>], lens: impl Iterator<Item = usize>) -> Vec<(Vec3, Vec3)> {
    let mut at = 0;
    lens.map(|n| {
        let b = starts[at..at + n]
            .iter()
            .flatten()
            .map(|s| s.bounds())
            .fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
            );
        at += n;
        b
    })
    .filter(|(lo, hi)| lo.x <= hi.x)
    .collect()
}

/// Whether the box `[tlo, thi]` can meet a segment from a point of the box
/// `[lo, hi]` (origins, z > 0) to a light point `(x, y, 0)`, `|x| <= h[0]`,
/// `|y| <= h[1]`: the segment from p to q is at depth z at the lateral
/// point `q + s (p − q)`, `s = z / p.z` in [0, 1]; over the origins' box and
/// the light, depth z holds the lateral interval
/// `[(1 − s)(−h) + s lo, (1 − s) h + s hi]` for s in `[z / hi.z, z / lo.z]`,
/// linear in s, so the box test takes its ends. Padded by 1e-4 of the
/// coordinates' size: a triangle grazing a shaft by rounding is kept.
fn in_shaft(tlo: Vec3, thi: Vec3, lo: Vec3, hi: Vec3, h: [f32; 2]) -> bool {
    let pad = 1e-4 * (1.0 + hi.abs().max_element().max(thi.abs().max_element()));
    let (z0, z1) = ((tlo.z - pad).max(0.0), (thi.z + pad).min(hi.z + pad));
    if z0 > z1 {
        return false;
    }
    let s0 = (z0 / hi.z.max(f32::MIN_POSITIVE)).min(1.0);
    let s1 = (z1 / lo.z.max(f32::MIN_POSITIVE)).min(1.0);
    (0..2).all(|a| {
        let low = |s: f32| (1.0 - s) * -h[a] + s * lo[a];
        let high = |s: f32| (1.0 - s) * h[a] + s * hi[a];
        let (min, max) = (low(s0).min(low(s1)), high(s0).max(high(s1)));
        thi[a] + pad >= min && tlo[a] - pad <= max
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::BackendChoice;
    use crate::eye::framing::{frame, traced_triangles};
    use crate::eye::gbuffer::SceneTriangles;
    use crate::eye::{Bias, CpuEye, EyeCall, EyeStages};
    use crate::geom::camera::Camera;
    use crate::geom::light::AreaLight;
    use crate::geom::light_space::Light;
    use crate::geom::mesh::MeshRef;
    use crate::methods::{ExactConfig, MethodConfig};

    /// Horizontal squares (height y, half-width h) facing up: each one's
    /// corners, and the two faces they share.
    fn squares(levels: &[(f64, f64)]) -> (Vec<Vec<[f64; 3]>>, Vec<[u32; 3]>) {
        let quad = |&(y, h): &(f64, f64)| vec![[-h, y, -h], [h, y, -h], [h, y, h], [-h, y, h]];
        (
            levels.iter().map(quad).collect(),
            vec![[0, 2, 1], [0, 3, 2]],
        )
    }

    fn meshes<'a>(squares: &'a [Vec<[f64; 3]>], faces: &'a [[u32; 3]]) -> Vec<MeshRef<'a>> {
        squares
            .iter()
            .map(|vertices| MeshRef { vertices, faces })
            .collect()
    }

    /// A floor, a block on it and a plate over it, seen from above at an
    /// angle under a 1 x 1 light: the estimate with each batch's rays
    /// through a culled BVH gives the very numbers of one whole-scene BVH.
    #[test]
    fn culling_the_triangles_changes_no_ray() {
        let (squares, faces) = squares(&[(0.0, 3.0), (1.0, 0.4), (2.0, 0.2)]);
        let meshes = meshes(&squares, &faces);
        let light = Light::Area(
            AreaLight::rect(
                [0.5, 4.0, 0.3],
                [0.0, -1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0],
            )
            .unwrap(),
        );
        let camera = Camera::look_at(
            [2.0, 3.0, 3.0],
            [0.0, 0.3, 0.0],
            [0.0, 1.0, 0.0],
            50.0,
            (96, 72),
        )
        .unwrap();
        let call = EyeCall {
            meshes: &meshes,
            light: &light,
            camera: &camera,
            method: MethodConfig::Exact(ExactConfig::of(16)),
            map_resolution: None,
            bias: Bias::new(None, None).unwrap(),
            backend: BackendChoice::Cpu,
            threads: None,
            estimate_error: Some(Draw::Timed),
            prepared: None,
            gbuffer: None,
        };
        let scene = SceneTriangles::new(&meshes).unwrap();
        let g = CpuEye.first_hits(&camera, &scene).unwrap();
        let f = frame(&call, &scene, &g).unwrap();
        // A made-up result: lit everywhere but a band, so both strata fill.
        let v: Vec<f32> = (0..f.hits.len())
            .map(|k| if k % 7 < 3 { 0.5 } else { 1.0 })
            .collect();
        let tris = traced_triangles(&f, &scene);
        let size = (camera.width, camera.height);
        // A budget no batch reaches: every unit is traced both ways.
        let whole = |t: &Vec<[Vec3; 3]>| Occluders::Triangles(t.clone());
        let a = estimate_with(&f, size, whole(&tris), &v, 64, (MAX_UNITS, 1e9), true);
        let b = estimate_with(&f, size, whole(&tris), &v, 64, (MAX_UNITS, 1e9), false);
        // Through `exact`'s own tree (its SAH build) too.
        let bvh = Bvh::build(tris.clone());
        let c = estimate_with(
            &f,
            size,
            Occluders::Tree(&bvh),
            &v,
            64,
            (MAX_UNITS, 1e9),
            true,
        );
        assert!(a.shadowed > 0 && a.traced == b.traced && a.traced == c.traced);
        for e in [&b, &c] {
            assert_eq!(
                (a.error, a.low, a.high, a.shadowed),
                (e.error, e.low, e.high, e.shadowed)
            );
        }
        // A fixed draw: PLANNED_UNITS units (96 x 72 has more), the same
        // estimate whatever the call has spent.
        let tris = traced_triangles(&f, &scene);
        let c = estimate(&f, size, tris.clone(), &v, 64, (Draw::Fixed, 1e-9));
        let d = estimate(&f, size, tris, &v, 64, (Draw::Fixed, 1e9));
        assert_eq!(c.traced, PLANNED_UNITS * UNIT);
        assert_eq!((c.error, c.high, c.traced), (d.error, d.high, d.traced));
    }

    /// A sphere over a floor and a plate, on an image small enough that a
    /// fixed draw takes every unit: the estimate is then the error itself,
    /// mean |V - V_ref| over the pixels the finer rays shadow, with an
    /// interval of zero width (no unit left undrawn).
    #[test]
    fn a_spheres_census_estimate_is_its_error() {
        use crate::eye::sphere_rays::{sphere_bvh, sphere_visibility};
        let (squares, faces) = squares(&[(0.0, 3.0), (1.0, 0.4)]);
        let meshes = meshes(&squares, &faces);
        let light = SphereLight::new([0.3, 2.5, 0.2], 0.6).unwrap();
        let camera = Camera::look_at(
            [2.0, 3.0, 3.0],
            [0.0, 0.3, 0.0],
            [0.0, 1.0, 0.0],
            50.0,
            (32, 24),
        )
        .unwrap();
        let scene = SceneTriangles::new(&meshes).unwrap();
        let g = CpuEye.first_hits(&camera, &scene).unwrap();
        let hits = g.hits();
        let bvh = sphere_bvh(&light, &scene.corners);
        let plain = |n: u32| -> Vec<f32> {
            sphere_visibility(&bvh, &light, &g, &hits, n, None)
                .into_iter()
                .map(|[v, _]| v)
                .collect()
        };
        let (result, reference) = (plain(4), plain(64));
        let (mut sum, mut count) = (0f64, 0usize);
        for (v, r) in result.iter().zip(&reference) {
            if 1.0 - r > SHADOW_THRESHOLD {
                sum += (v - r).abs() as f64;
                count += 1;
            }
        }
        assert!(hits.len() <= PLANNED_UNITS * UNIT && count > 50);
        let e = estimate_sphere((&bvh, &light), &g, &hits, &result, 64, (Draw::Fixed, 0.0));
        let truth = sum / count as f64;
        assert!(truth > 0.01, "{truth}");
        assert_eq!((e.traced, e.shadowed), (hits.len(), count));
        assert!((e.error - truth).abs() < 1e-9, "{} {truth}", e.error);
        assert!((e.high - e.low).abs() < 1e-9);
    }

    /// Every box a sampled segment from the origins' box to the light
    /// passes through is kept; boxes far off every segment are not.
    #[test]
    fn the_shaft_test_keeps_every_box_a_segment_meets() {
        let mut s = 7u64;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % 1_000_000) as f32 / 1e6
        };
        let h = [0.3f32, 0.2];
        let (lo, hi) = (Vec3::new(0.1, -0.2, 2.0), Vec3::new(0.25, -0.1, 2.3));
        let (mut kept, mut dropped) = (0, 0);
        for _ in 0..4000 {
            let c = Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, r() * 2.6);
            let e = Vec3::new(r(), r(), r()) * 0.05;
            let (tlo, thi) = (c - e, c + e);
            let meets = (0..400).any(|_| {
                let p = lo + (hi - lo) * Vec3::new(r(), r(), r());
                let q = Vec3::new((r() * 2.0 - 1.0) * h[0], (r() * 2.0 - 1.0) * h[1], 0.0);
                let x = q + (p - q) * r();
                x.cmplt(thi).all() && x.cmpgt(tlo).all()
            });
            let test = in_shaft(tlo, thi, lo, hi, h);
            if meets {
                assert!(test, "{tlo} {thi}");
            }
            if test {
                kept += 1;
            } else {
                dropped += 1;
            }
        }
        // The test is a cull, not a pass-through: most far boxes go.
        assert!(dropped > 2 * kept, "{kept} kept, {dropped} dropped");
    }
}
