//! The shadow rays of many receivers toward stratified samples of the
//! light: which are traced, in what groups, and what each receiver sees.
//!
//! Each receiver sends one ray to a jittered point in each stratum of an
//! a x b grid over the light (`LightShape::samples`); the jitter is a hash
//! of the stratum, the same for every receiver (`Jitter::Shared`: one fine
//! multi-jittered pattern, so that a penumbra changes from pixel to pixel
//! as the geometry does, in steps of one sample, without per-pixel grain),
//! or also of the receiver's key (`Jitter::PerReceiver`: the probe's, whose
//! neighbours must test different points). Results are deterministic and the same on
//! the GPU (`gpu/exact.wgsl`, which traces every ray). What the CPU skips
//! or groups never changes a ray's answer:
//!
//! 1. A receiver whose shaft to the whole light meets no leaf of the BVH
//!    is lit without a ray (`shaft.rs`): 34% of the receivers of the
//!    floating bunny at 256².
//! 2. The others go in packets of `LANES` consecutive receivers (callers
//!    order them in tiles, `tile_order`, so that they are neighbours). A
//!    packet's shaft to each region of `REGION` x `REGION` strata is
//!    tested once; the rays of a clear region are counted lit untraced
//!    (on the floating bunny, 5.7 M of the 11.1 M rays of the receivers
//!    step 1 left).
//! 3. The rest are traced a stratum at a time, the packet's eight rays
//!    together (`packet.rs`: a four-wide BVH, AVX2 lanes), first through
//!    the subtree that blocked the packet's last blocked ray (a shadow
//!    cache, after Haines & Greenberg 1986: neighbouring strata are
//!    usually blocked by nearby triangles), then from the root.
//!
//! Timings and the variants tried are in docs/methods/exact.md.

use super::bvh::Bvh;
use super::packet::{Mask, Rays, ALL, LANES};
use super::shaft::is_clear;
use crate::geom::light_shape::LightSamples;
use glam::Vec3;
use rayon::prelude::*;

/// Shadow rays start this fraction of the way from the receiver and stop this
/// fraction short of the light: occluders touching the receiver or the light
/// are not hit by rounding alone.
pub(crate) const RAY_EPS: f32 = 1e-5;

/// A 32-bit mix (splitmix-style) for deterministic jitter.
#[inline]
fn hash(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// A permutation of [0, l) keyed by `seed`: bijections of [0, 2^k) (xor,
/// odd multiplications and xorshifts, masked), applied again while the
/// value is l or more (cycle walking: under two steps on average, 2^k < 2 l,
/// and never more than 2^k - l + 1, the values a cycle can hold at or above
/// l in a row: bounded on the GPU too).
#[inline]
fn permute(mut i: u32, l: u32, seed: u32) -> u32 {
    let w = l.next_power_of_two() - 1;
    loop {
        i = (i ^ seed) & w;
        i = i.wrapping_mul(0x9E37_79B1) & w;
        i ^= i >> 1;
        i = i.wrapping_add(seed >> 8) & w;
        i = i.wrapping_mul(0x85EB_CA6B) & w;
        i ^= i >> 2;
        if i < l {
            return i;
        }
    }
}

/// The largest f32 below 1: a jitter stays inside its stratum.
const BELOW_ONE: f32 = 0.999_999_94;

/// The shared pattern's jitter (ja, jb) of stratum (sa, sb) of `grid`
/// (`Jitter::Shared`); `hs` the stratum's hash. `exact.wgsl`'s
/// `multi_jitter` is its twin, in the same operations.
#[inline]
fn multi_jitter(sa: u32, sb: u32, grid: (u32, u32), hs: u64) -> (f32, f32) {
    let (na, nb) = grid;
    let column = permute(sb, nb, hash(u64::from(sa) ^ 0x51) as u32);
    let row = permute(sa, na, hash(u64::from(sb) ^ 0xA7) as u32);
    let h = hash(hs);
    let ja = (column as f32 + unit(h)) / nb as f32;
    let jb = (row as f32 + unit(hash(h))) / na as f32;
    (ja.min(BELOW_ONE), jb.min(BELOW_ONE))
}

#[inline]
fn unit(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// Where a receiver's shadow rays start: a box holding every origin (where
/// its shaft starts), and the origin of the ray toward the light point
/// (x, y, 0).
pub(crate) trait RayOrigin: Sync {
    fn bounds(&self) -> (Vec3, Vec3);
    fn origin(&self, x: f32, y: f32) -> Vec3;
    /// Whether `weight` varies (else every sample weighs 1, and a clear
    /// region's samples are counted without computing their points).
    const WEIGHTED: bool = false;
    /// The weight of the light point (x, y) in the receiver's irradiance
    /// (`visibilities_weighted`), up to a factor common to its samples; 1
    /// where the receiver has no surface (the light view's points).
    #[inline(always)]
    fn weight(&self, _x: f32, _y: f32) -> f32 {
        1.0
    }
    /// The Lambertian surface point behind `weight`, where it has one.
    #[inline(always)]
    fn surface(&self) -> Option<SurfacePoint> {
        None
    }
    /// Every origin `origin` gives, and which light points each serves
    /// (`masks/`, which works origin by origin).
    #[inline(always)]
    fn origins(&self) -> Origins {
        Origins::One(self.origin(0.0, 0.0))
    }
}

/// A receiver by reference: the masks hand the receivers they leave to the
/// rays this way (`engine.rs`).
impl<R: RayOrigin> RayOrigin for &R {
    const WEIGHTED: bool = R::WEIGHTED;
    #[inline(always)]
    fn bounds(&self) -> (Vec3, Vec3) {
        (*self).bounds()
    }
    #[inline(always)]
    fn origin(&self, x: f32, y: f32) -> Vec3 {
        (*self).origin(x, y)
    }
    #[inline(always)]
    fn weight(&self, x: f32, y: f32) -> f32 {
        (*self).weight(x, y)
    }
    #[inline(always)]
    fn surface(&self) -> Option<SurfacePoint> {
        (*self).surface()
    }
    #[inline(always)]
    fn origins(&self) -> Origins {
        (*self).origins()
    }
}

/// A receiver's ray origins: one for every light point, or two, `above`
/// for the light points (x, y) with side[0] + x side[1] + y side[2] >= 0
/// (in that order of operations, f32) and `below` for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Origins {
    One(Vec3),
    Two {
        above: Vec3,
        below: Vec3,
        side: [f32; 3],
    },
}

/// A Lambertian surface point p (kernel space) and its tangent plane,
/// side(x, y) = side[0] + x side[1] + y side[2] (n · (y - p) up to a
/// positive factor): the light point (x, y, 0)'s share of its irradiance
/// under a planar light sampled uniformly over its area is cos θ cos θ' /
/// r², with cos θ = side / r (0 below the horizon) and cos θ' = p_z / r
/// (the light faces +Z): side · p_z / r⁴.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SurfacePoint {
    pub p: Vec3,
    pub side: [f32; 3],
}

impl SurfacePoint {
    #[inline(always)]
    pub fn weight(&self, x: f32, y: f32) -> f32 {
        let side = self.side[0] + x * self.side[1] + y * self.side[2];
        let r2 = (Vec3::new(x, y, 0.0) - self.p).length_squared();
        side.max(0.0) * self.p.z / (r2 * r2)
    }
}

/// The midpoint rule's side for the weights over the whole light.
pub const QUAD: usize = 32;

/// ∫ w over the light [-1, 1]² (half-extents `half` in kernel units) seen
/// from `s`, in units where the whole light's area is 4 (the SSM's
/// occlusion sums, `ssm/weighted.rs`; PCSS's weighted filter divides by a
/// quarter of it, `pcss_weighted.rs`): 4 times the mean of w at the QUAD²
/// midpoints, a row's in f32 (computed side by side), the rows in f64.
/// Under a disk (the unit disk in those units) the mean is over the
/// midpoints inside it (812 of 1024), so that its area counts as the 4 the
/// disk's clipped sums reach.
pub fn light_weight(s: &SurfacePoint, half: [f32; 2], disk: bool) -> f64 {
    let step = 2.0 / QUAD as f32;
    let us: [f32; QUAD] = std::array::from_fn(|i| -1.0 + (i as f32 + 0.5) * step);
    let xs: [f32; QUAD] = us.map(|u| u * half[0]);
    let on = |u: f32, v: f32| !disk || u * u + v * v <= 1.0;
    let (mut sum, mut count) = (0f64, 0usize);
    for &v in &us {
        let y = v * half[1];
        let row: [f32; QUAD] = std::array::from_fn(|i| {
            if on(us[i], v) {
                s.weight(xs[i], y)
            } else {
                0.0
            }
        });
        sum += f64::from(row.iter().sum::<f32>());
        count += us.iter().filter(|&&u| on(u, v)).count();
    }
    4.0 * sum / count as f64
}

/// A receiver point (the light view).
impl RayOrigin for Vec3 {
    #[inline(always)]
    fn bounds(&self) -> (Vec3, Vec3) {
        (*self, *self)
    }
    #[inline(always)]
    fn origin(&self, _x: f32, _y: f32) -> Vec3 {
        *self
    }
}

/// Whose jitter a receiver's samples take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Jitter {
    /// One pattern every receiver shares (the answer's rays), multi-jittered
    /// (Chiu, Shirley & Wang 1994): each stratum's sample also takes its own
    /// sub-column of the stratum's column and sub-row of its row (a hashed
    /// permutation per column and per row, `permute`), so the a*b samples
    /// project onto a*b distinct columns and rows of the light, and an edge
    /// across the light uncovers them one at a time. (The bitmask's pattern,
    /// `bitmask.rs`, is built the same way as tables of ranks for square
    /// grids; here each sample is computed alone, any a x b, so the GPU
    /// needs no table.)
    ///
    /// Chosen on the as-built calibration scenes and the eye-view scenes at
    /// 320x240 (against 4096-sample references; the held-out scenes were
    /// measured once after, docs/accuracy.md): with a pattern per receiver,
    /// neighbouring penumbra pixels differ by the patterns' noise; one
    /// jittered pattern shared halved that grain (mean |V - box3x3(V)| on
    /// penumbra pixels over the reference's: +0.0035 to +0.0018 on
    /// blocks_on_table, +0.0039 to +0.0021 on room_window, 256 samples) but
    /// one draw's error is not the average draw's (64 samples on
    /// contact_boxes: 0.0174 where per-pixel patterns gave 0.0130 in
    /// bench_eye); the multi-jittered one errs 16-51% less than the plainly
    /// jittered one at 64 samples (contact_boxes 0.0174 to 0.0085,
    /// blocks_on_table 0.0126 to 0.0073) and 0-32% less at 256 (0.0044 to
    /// 0.0030; shelf_with_objects the exception, 0.0029 to 0.0031), its
    /// grain the same or lower.
    Shared,
    /// A pattern per receiver, hashed with its key: the probe's, whose nine
    /// neighbours' 16 samples then test 144 light points, not 16 (with a
    /// shared probe the default call erred up to 0.0005 more than `exact`
    /// alone on the calibration scenes: blocks_on_table 0.0044 against
    /// 0.0039).
    PerReceiver,
}

/// The light samples every receiver's rays go to, and where rays start.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sampling {
    /// The strata and where their samples lie (`LightShape::samples`).
    pub light: LightSamples,
    /// Segments are t in (t0, 1 - RAY_EPS) of origin to light point.
    pub t0: f32,
    pub jitter: Jitter,
}

impl Sampling {
    /// The box of the light holding strata [a0, a1) x [b0, b1).
    fn rect(&self, a0: u32, a1: u32, b0: u32, b1: u32) -> [[f32; 2]; 2] {
        self.light.region(a0, a1, b0, b1)
    }

    /// The light point of sample (sa, sb) for the receiver whose jitter
    /// key is `key` (unused when the pattern is shared).
    pub(crate) fn sample(&self, key: u64, sa: u32, sb: u32) -> (f32, f32) {
        let na = self.light.grid.0;
        self.point(key, hash(((sb * na + sa) as u64) << 1), sa, sb)
    }

    /// The shared pattern's light points (every receiver's), row-major by
    /// stratum: sample (sa, sb) at sb * a + sa.
    pub(crate) fn shared_points(&self) -> Vec<(f32, f32)> {
        let (na, nb) = self.light.grid;
        (0..nb)
            .flat_map(|sb| (0..na).map(move |sa| (sa, sb)))
            .map(|(sa, sb)| self.sample(0, sa, sb))
            .collect()
    }

    /// `sample`, with `hs` = `hash(((sb * na + sa) as u64) << 1)`, which
    /// every receiver shares.
    #[inline(always)]
    fn point(&self, key: u64, hs: u64, sa: u32, sb: u32) -> (f32, f32) {
        if self.jitter == Jitter::Shared {
            let (ja, jb) = multi_jitter(sa, sb, self.light.grid, hs);
            return self.light.point(sa, sb, ja, jb);
        }
        let h = hash(key ^ hs);
        self.light.point(sa, sb, unit(h), unit(hash(h)))
    }
}

/// Strata per side of a light region whose shaft is tested per packet
/// (more where that would make over `MAX_REGIONS` per side).
const REGION: u32 = 4;
const MAX_REGIONS: u32 = 8;
/// Shadow cache: the subtree this many wide levels above the leaf that
/// blocked the last blocked ray is searched first.
const CACHE_LEVELS: u32 = 1;

/// Receivers per parallel task (each packs its own).
const CHUNK: usize = 64;

/// The visibility of each receiver of `receivers` (`absent` for `None`):
/// the fraction of its stratified light samples whose segment is clear,
/// the jitter a hash of its key `key(k)` (receiver k's texel or pixel: see
/// below) and the sample. `order` (a permutation of the receivers' indices)
/// is the order to trace them in: `LANES` consecutive ones go in a packet,
/// so neighbours should be consecutive (`tile_order`).
///
/// The key names where the receiver is (its texel, its pixel), not its rank
/// among the receivers traced: a rank shifts by one after any pixel that
/// one backend sees and the other does not (the CPU rasterizes the first
/// hits, the GPU casts them: they differ where a pixel centre grazes an
/// edge), and every pixel after it would get another sample pattern
/// (issue 28: 1.4-32% of the pixels' visibilities differed by multiples of
/// one sample's weight).
pub(crate) fn visibilities<R: RayOrigin>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    s: &Sampling,
    absent: f32,
) -> Vec<f32> {
    visibilities_weighted(bvh, receivers, key, order, s, absent)
        .into_iter()
        .map(|[v, _]| v)
        .collect()
}

/// `visibilities`, each receiver's with the weighted fraction beside it:
/// `[V, V_w]`, V_w = Σ clear w_i / Σ w_i over its samples, w_i its
/// `RayOrigin::weight` at sample i's light point (the same rays: V_w is V
/// with each sample weighted by what it adds to the irradiance, the ratio
/// estimator of Heitz, Hill and McGuire 2018). A receiver whose shaft is
/// clear, or whose samples weigh nothing (the light below its horizon),
/// has V_w = V.
pub(crate) fn visibilities_weighted<R: RayOrigin>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    s: &Sampling,
    absent: f32,
) -> Vec<[f32; 2]> {
    debug_assert_eq!(order.len(), receivers.len());
    let light = s.rect(0, s.light.grid.0, 0, s.light.grid.1);
    // The shared pattern's points, every receiver's: computed once a call,
    // not once a packet (its two permutations' walks and four hashes ran 8
    // times a sample in `trace_packet` once, 16% of a profile of Exact(64)
    // on bench_scale's mesh_125k).
    let shared: Option<Vec<(f32, f32)>> = (s.jitter == Jitter::Shared).then(|| s.shared_points());
    // A cancelled call's remaining packets are skipped (`crate::cancel`).
    let stop = crate::cancel::current();
    let traced: Vec<Vec<(usize, [f32; 2])>> = order
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            if stop.is_cancelled() {
                return out;
            }
            let mut pending: Vec<(u64, &R)> = Vec::with_capacity(chunk.len());
            let mut keys = Vec::with_capacity(chunk.len());
            for &k in chunk {
                let Some(r) = &receivers[k] else { continue };
                let (lo, hi) = r.bounds();
                if is_clear(bvh, lo, hi, light) {
                    // Every sample would be counted: the same 1.0 as tracing.
                    out.push((k, [1.0; 2]));
                } else {
                    pending.push((key(k), r));
                    keys.push(k);
                }
            }
            for (group, keys) in pending.chunks(LANES).zip(keys.chunks(LANES)) {
                if stop.is_cancelled() {
                    break;
                }
                let v = trace_packet(bvh, group, s, shared.as_deref());
                out.extend(keys.iter().copied().zip(v));
            }
            out
        })
        .collect();
    let mut v = vec![[absent; 2]; receivers.len()];
    for (k, x) in traced.into_iter().flatten() {
        v[k] = x;
    }
    v
}

/// The visibility of up to `LANES` receivers `(key, origin)`, their rays
/// traced together, and their weighted visibility; `shared`: the shared
/// pattern's points, row-major by stratum (None: a pattern per receiver).
fn trace_packet<R: RayOrigin>(
    bvh: &Bvh,
    group: &[(u64, &R)],
    s: &Sampling,
    shared: Option<&[(f32, f32)]>,
) -> [[f32; 2]; LANES] {
    let m = group.len();
    debug_assert!((1..=LANES).contains(&m));
    let valid: Mask = if m == LANES { ALL } else { (1 << m) - 1 };
    // Unused lanes repeat the last receiver (masked off).
    let lane = |i: usize| group[i.min(m - 1)];
    let (na, nb) = s.light.grid;
    let t1 = 1.0 - RAY_EPS;

    // The packet's origins, and which regions of strata their shaft
    // leaves clear (every ray there sees the light).
    let (mut lo, mut hi) = lane(0).1.bounds();
    for i in 1..m {
        let (a, b) = lane(i).1.bounds();
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let side = |n: u32| REGION.max(n.div_ceil(MAX_REGIONS));
    let (sa_r, sb_r) = (side(na), side(nb));
    let (ra, rb) = (na.div_ceil(sa_r), nb.div_ceil(sb_r));
    let mut clear = [false; (MAX_REGIONS * MAX_REGIONS) as usize];
    for rj in 0..rb {
        for ri in 0..ra {
            let (a0, b0) = (ri * sa_r, rj * sb_r);
            let rect = s.rect(a0, (a0 + sa_r).min(na), b0, (b0 + sb_r).min(nb));
            clear[(rj * ra + ri) as usize] = is_clear(bvh, lo, hi, rect);
        }
    }

    let mut seen = [0u32; LANES];
    // Each lane's weights: of its clear samples, and of all of them (f64:
    // 16 384 samples of weights spanning decades).
    let mut w_seen = [0f64; LANES];
    let mut w_all = [0f64; LANES];
    let mut cache: Option<u32> = None;
    for sb in 0..nb {
        for sa in 0..na {
            let region_clear = clear[((sb / sb_r) * ra + sa / sa_r) as usize];
            if region_clear && !R::WEIGHTED {
                for i in 0..LANES {
                    seen[i] += 1;
                    w_seen[i] += 1.0;
                    w_all[i] += 1.0;
                }
                continue;
            }
            let hs = hash(((sb * na + sa) as u64) << 1);
            // The shared pattern's point is every lane's.
            let shared = shared.map(|t| t[(sb * na + sa) as usize]);
            let mut o = [Vec3::ZERO; LANES];
            let mut d = [Vec3::ZERO; LANES];
            let mut w = [0f64; LANES];
            for i in 0..LANES {
                let (key, r) = lane(i);
                let (x, y) = shared.unwrap_or_else(|| s.point(key, hs, sa, sb));
                o[i] = r.origin(x, y);
                d[i] = Vec3::new(x, y, 0.0) - o[i];
                w[i] = f64::from(r.weight(x, y));
                w_all[i] += w[i];
            }
            if region_clear {
                for i in 0..LANES {
                    seen[i] += 1;
                    w_seen[i] += w[i];
                }
                continue;
            }
            let rays = Rays::new(o, d);
            let mut open = valid;
            for from in [cache, Some(0)].into_iter().flatten() {
                if open == 0 {
                    break;
                }
                let (blocked, node) = bvh.occluded_lanes(from, &rays, open, s.t0, t1);
                open &= !blocked;
                if let Some(w) = node {
                    cache = Some(bvh.wide_ancestor(w, CACHE_LEVELS));
                }
            }
            for (i, n) in seen.iter_mut().enumerate() {
                let lit = (open >> i) & 1;
                *n += lit as u32;
                if lit == 1 {
                    w_seen[i] += w[i];
                }
            }
        }
    }
    std::array::from_fn(|i| {
        let v = seen[i] as f32 / (na * nb) as f32;
        let vw = if w_all[i] > 0.0 {
            (w_seen[i] / w_all[i]) as f32
        } else {
            v
        };
        [v, vw]
    })
}

/// The indices of a width x height grid in tiles of 4 x 2 (row-major
/// tiles, row-major within one), so that `LANES` consecutive indices are
/// neighbours.
pub(crate) fn tile_order(width: usize, height: usize) -> Vec<usize> {
    let mut order = Vec::with_capacity(width * height);
    for ty in (0..height).step_by(2) {
        for tx in (0..width).step_by(4) {
            for y in ty..(ty + 2).min(height) {
                for x in tx..(tx + 4).min(width) {
                    order.push(y * width + x);
                }
            }
        }
    }
    order
}

#[cfg(test)]
mod pattern_tests {
    use super::{multi_jitter, permute};
    use std::collections::HashSet;

    #[test]
    fn permute_is_a_permutation_of_every_length() {
        for l in 1..=300 {
            for seed in [0, 1, 0x51, 0xdead_beef, u32::MAX] {
                let got: HashSet<u32> = (0..l).map(|i| permute(i, l, seed)).collect();
                assert_eq!(got.len(), l as usize, "l {l} seed {seed}");
                assert!(got.iter().all(|&v| v < l));
            }
        }
    }

    #[test]
    fn the_shared_pattern_is_multi_jittered_on_any_grid() {
        for (na, nb) in [(1, 1), (4, 4), (16, 16), (8, 32), (3, 5), (1, 17)] {
            let n = (na * nb) as f32;
            let (mut columns, mut rows) = (HashSet::new(), HashSet::new());
            for sb in 0..nb {
                for sa in 0..na {
                    let hs = super::hash(u64::from(sb * na + sa) << 1);
                    let (ja, jb) = multi_jitter(sa, sb, (na, nb), hs);
                    // Inside its stratum.
                    assert!((0.0..1.0).contains(&ja) && (0.0..1.0).contains(&jb));
                    // Its column and row of the a*b x a*b fine grid.
                    let x = (sa as f32 + ja) / na as f32;
                    let y = (sb as f32 + jb) / nb as f32;
                    columns.insert((x * n) as u32);
                    rows.insert((y * n) as u32);
                }
            }
            assert_eq!(columns.len(), (na * nb) as usize, "{na} x {nb}");
            assert_eq!(rows.len(), (na * nb) as usize, "{na} x {nb}");
        }
    }
}
