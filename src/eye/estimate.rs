//! The eye view's error estimate (`estimate_error=True`, always on for
//! `Auto` with a target): exact stratified rays (`rays.rs`, the `exact` method's own) at
//! a random subset of the visible pixels, compared with the result there
//! (the statistics: `crate::error_estimate`).
//!
//! The pixels are drawn in units of a 4 x 2 tile (their rays go in one
//! coherent packet; scattered single pixels traced 7 times slower), in two
//! strata: the units in the result's shadow (visibility below 1 − 0.001),
//! where the error lives, get three quarters of the draw; the lit rest a
//! quarter (a shadow the result missed is found there). A pilot of `PILOT`
//! units is timed, then as many more are traced as fit in `SHARE` of the
//! call so far, at most `MAX_UNITS`. The BVH is the quick Morton one
//! (`Bvh::build_fast`): for a few thousand pixels its build is most of the
//! cost. The estimate runs on the CPU for both backends.

use std::time::Instant;

use glam::Vec3;

use super::framing::Framed;
use super::rays;
use crate::error_estimate::{draw, ratio_estimate, ErrorEstimate, Stratum, SHADOW_THRESHOLD};
use crate::methods::exact::Bvh;

/// Light samples of the exact rays at each drawn pixel, for a result of
/// the map methods: their stratified error (about 1/256 in a penumbra) is
/// well below the errors the estimate tells apart.
pub const REFERENCE_SAMPLES: u32 = 256;
/// Neighbouring pixels traced together (a 4 x 2 tile, one packet of rays).
pub const UNIT: usize = 8;
/// The units of the timed pilot (128 pixels).
pub const PILOT: usize = 16;
/// The most units traced (16384 pixels).
pub const MAX_UNITS: usize = 2048;
/// The estimate's share of the call's time: at most a ninth of the rest
/// (a tenth of the whole).
pub const SHARE: f64 = 1.0 / 9.0;
/// The share of the drawn units taken in the result's shadow.
const SHADOW_SHARE: f64 = 0.75;

/// The estimate of `visibility` (per visible point of `f`, in its order)
/// against exact rays with `samples` light samples through `triangles`
/// (kernel light space: every triangle that can shadow a point), the
/// image `width` x `height`, the call having taken `spent` seconds so far.
pub fn estimate(
    f: &Framed,
    (width, height): (usize, usize),
    triangles: Vec<[Vec3; 3]>,
    visibility: &[f32],
    samples: u32,
    spent: f64,
) -> ErrorEstimate {
    let t0 = Instant::now();
    // Units: runs of UNIT visible points in 4 x 2 tile order (mostly whole
    // tiles), in the result's shadow when any of their pixels is.
    let tiled = rays::tiled(&f.hits, width, height);
    let units: Vec<&[usize]> = tiled.chunks(UNIT).collect();
    let (shadow, lit): (Vec<usize>, Vec<usize>) = (0..units.len()).partition(|&u| {
        units[u]
            .iter()
            .any(|&k| 1.0 - visibility[k] > SHADOW_THRESHOLD)
    });
    let bvh = Bvh::build_fast(triangles);
    let mut strata = [Stratum::default(), Stratum::default()];
    strata[0].population = shadow.len();
    strata[1].population = lit.len();
    let mut traced = 0;
    let mut trace = |total: usize, strata: &mut [Stratum; 2]| {
        let want0 = ((total as f64 * SHADOW_SHARE).round() as usize).min(shadow.len());
        let want1 = (total - want0).min(lit.len());
        let want0 = (total - want1).min(shadow.len());
        let (had0, had1) = (strata[0].drawn.len(), strata[1].drawn.len());
        // A longer draw extends the pilot's (`draw`'s prefixes).
        let new: Vec<usize> = draw(shadow.len(), want0, 1)[had0..]
            .iter()
            .map(|&i| shadow[i])
            .chain(draw(lit.len(), want1, 2)[had1..].iter().map(|&i| lit[i]))
            .collect();
        let pixels: Vec<usize> = new.iter().flat_map(|&u| units[u].iter().copied()).collect();
        let points: Vec<[f64; 3]> = pixels.iter().map(|&k| f.points[k]).collect();
        let normals: Vec<[f32; 3]> = pixels.iter().map(|&k| f.normals[k]).collect();
        let starts = rays::ray_starts(&f.space, f.unit, &points, &normals);
        let identity: Vec<usize> = (0..pixels.len()).collect();
        // Each pixel's samples are keyed by its place in the image, as
        // `exact`'s are: with the same samples the estimate's rays are the
        // full image's.
        let key = |j: usize| f.hits[pixels[j]] as u64;
        let exact = rays::visibility_in(&bvh, f.light_shape, &starts, key, &identity, samples);
        let mut at = 0;
        for (j, &u) in new.iter().enumerate() {
            let pairs = units[u]
                .iter()
                .zip(&exact[at..])
                .map(|(&k, &r)| (visibility[k], r))
                .collect();
            at += units[u].len();
            strata[(j >= want0 - had0) as usize].drawn.push(pairs);
        }
        traced += pixels.len();
        new.len()
    };
    let mut drawn = trace(PILOT.min(units.len()), &mut strata);
    let pilot_seconds = t0.elapsed().as_secs_f64();
    // The pilot's time per unit (its BVH included: an upper bound) sets
    // how many more fit in the budget.
    let per_unit = pilot_seconds / drawn.max(1) as f64;
    let budget = SHARE * spent - pilot_seconds;
    if budget > 0.0 && per_unit > 0.0 {
        let more = (budget / per_unit) as usize;
        let total = (drawn + more).min(MAX_UNITS).min(units.len());
        if total > drawn {
            drawn += trace(total, &mut strata);
        }
    }
    debug_assert_eq!(drawn, strata[0].drawn.len() + strata[1].drawn.len());
    let (error, low, high, shadowed) = ratio_estimate(&strata);
    ErrorEstimate {
        error,
        low,
        high,
        traced,
        shadowed,
        samples,
        seconds: t0.elapsed().as_secs_f64(),
    }
}
