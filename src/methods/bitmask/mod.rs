//! Bitmask soft shadow maps (after Schwarz & Stamminger 2007, "Bitmask soft
//! shadows"): the light is sampled by a fixed set of points, and each
//! micro-patch marks, in a bit mask per receiver, the samples its
//! back-projection covers. Masks are merged by OR, so where back-projections
//! overlap the light counts once (the published SSM adds them: too dark in the
//! outer penumbra, §4.1.2); both occluder layers OR into the same mask.
//!
//! The samples form a multi-jittered pattern of n x n points (n = 4, 8, 16
//! or 32): one point per cell of an n x n grid, and one per each of the n^2
//! columns and n^2 rows of a fine grid. Back-projected micro-patches are
//! axis-aligned rectangles, so the samples inside [a, b] x [c, d] are those
//! whose x-rank lies in one range and y-rank in another: four table lookups
//! of "samples with rank >= k" and three ANDs, and a rectangle's edge is
//! placed to within 1/n^2 of the light's width. The pattern is the same for
//! every receiver (deterministic, no noise; its error is structured but small).
//!
//! Gaps (`Gaps`): with `Closed` (the default) each texel is a micro-quad
//! whose corners carry the depths that connect it to its neighbours
//! (`gather/corners.rs`), back-projected as the bounding rectangle of its
//! four projected corners: no light passes between connected neighbours.
//! `Open` keeps the flat per-texel micro-patches, whose gaps between
//! neighbours at different depths leak light inside the penumbra (§4.1.2).
//!
//! Its config (`BitmaskConfig`, its checks and its `MethodSpec`: name,
//! string form, resolution, capabilities row) is at the end of this file.

use super::config::{
    check_passes, check_resolution, hierarchy_option, occluder_resolution_option, passes_option,
    resolve_maps, CallContext, LooseOptions, MethodSpec, DEFAULT_PASSES, DEFAULT_SAMPLES,
    PRECISION_SSM_ONLY,
};
use super::gather::work::{BITMASK_1024_VISIT, BITMASK_VISIT};
use super::gather::{
    self, maps_with_levels, Accumulator, Group, Hierarchy, Lanes, RowLanes, HIERARCHY, LANES,
    ROWS_PER_GROUP, TILE_W,
};
use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::kernel::Kernel;
use super::keywords::{count, flag, resolution, KeywordForm, Keywords};
use super::Input;
use super::{EyePoints, LightPoint, ShadowInputs, ShadowMethod};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::geom::light_shape::LightShape;
use glam::Vec4;

/// A set of up to 64 W light samples.
type Mask<const W: usize> = [u64; W];

/// Sample counts the method accepts.
pub const SAMPLE_COUNTS: [u32; 4] = [16, 64, 256, 1024];

/// How neighbouring micro-patches meet (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Gaps {
    /// Connected micro-quads: no light between connected neighbours.
    #[default]
    Closed,
    /// Flat per-texel micro-patches, as the SSM has them.
    Open,
}

impl Gaps {
    pub const ALL: [Gaps; 2] = [Gaps::Closed, Gaps::Open];

    /// The name a user passes as `gaps=`.
    pub fn name(self) -> &'static str {
        match self {
            Gaps::Closed => "closed",
            Gaps::Open => "open",
        }
    }

    pub fn parse(name: &str) -> Option<Gaps> {
        Gaps::ALL.into_iter().find(|g| g.name() == name)
    }
}

/// The bitmask method with n x n light samples.
pub struct Bitmask {
    pattern: Patterns,
    gaps: Gaps,
    hierarchy: Option<Hierarchy>,
    /// The pattern holds a disk's samples only (`Pattern::new`).
    disk: bool,
}

/// The pattern in the narrowest mask that holds it.
enum Patterns {
    /// Up to 256 samples.
    Small(Pattern<4>),
    /// 1024 samples.
    Large(Pattern<16>),
}

/// The sample pattern as lookup tables of rank prefixes.
struct Pattern<const W: usize> {
    /// Samples per axis of the coarse grid; n^2 samples in all.
    n: usize,
    /// `x_ge[k]`: the samples whose x-rank is >= k, k in 0..=n^2 (of the
    /// samples on the light: for a disk, those inside it).
    x_ge: Vec<Mask<W>>,
    y_ge: Vec<Mask<W>>,
    /// The samples on the light (n^2 for a rectangle).
    counted: usize,
}

/// Whether the sample of ranks (xr, yr) of `s` lies on the disk inscribed
/// in the light's square: its light coordinates (half-light units, where
/// `RankBounds` puts rank k at 2 (k + 1/2)/S - 1) within the unit circle.
/// A disk is the square's samples inside it: ~pi/4 of them (201 of 256),
/// the rim placed to within a sample's cell.
fn on_disk(xr: usize, yr: usize, s: usize) -> bool {
    let t = |k: usize| 2.0 * (k as f64 + 0.5) / s as f64 - 1.0;
    t(xr).powi(2) + t(yr).powi(2) <= 1.0
}

fn set<const W: usize>(m: &mut Mask<W>, bit: usize) {
    m[bit / 64] |= 1 << (bit % 64);
}

/// A deterministic permutation of 0..n (Fisher-Yates over a fixed LCG).
fn permutation(n: usize, seed: &mut u64) -> Vec<usize> {
    let mut p: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let j = ((*seed >> 33) as usize) % (i + 1);
        p.swap(i, j);
    }
    p
}

/// The samples of the n x n pattern on the light (for a `disk`, those
/// inside it, `on_disk`): (bit, (x-rank, y-rank)).
fn sample_ranks(n: usize, disk: bool) -> impl Iterator<Item = (usize, (usize, usize))> {
    let mut seed = 0x5eed_u64 ^ n as u64;
    // Cell (i, j): x-rank i n + sigma_i(j), y-rank j n + tau_j(i).
    let sigma: Vec<Vec<usize>> = (0..n).map(|_| permutation(n, &mut seed)).collect();
    let tau: Vec<Vec<usize>> = (0..n).map(|_| permutation(n, &mut seed)).collect();
    (0..n * n)
        .map(move |bit| {
            let (i, j) = (bit % n, bit / n);
            (bit, (i * n + sigma[i][j], j * n + tau[j][i]))
        })
        .filter(move |&(_, (xr, yr))| !disk || on_disk(xr, yr, n * n))
}

/// The samples of `samples` on the light (`sample_ranks`): what a mask's
/// hidden count is a fraction of, on both backends.
pub fn counted_samples(samples: u32, disk: bool) -> u32 {
    let n = (samples as f64).sqrt().round() as usize;
    sample_ranks(n, disk).count() as u32
}

impl<const W: usize> Pattern<W> {
    /// The n x n pattern; `disk`: only its samples on the inscribed disk
    /// (`on_disk`) are in the tables.
    fn new(n: usize, disk: bool) -> Pattern<W> {
        let s = n * n;
        assert!(s <= 64 * W, "{s} samples do not fit {W} words");
        let mut x_ge = vec![[0u64; W]; s + 1];
        let mut y_ge = vec![[0u64; W]; s + 1];
        let mut counted = 0;
        for (bit, (xr, yr)) in sample_ranks(n, disk) {
            counted += 1;
            for m in &mut x_ge[..=xr] {
                set(m, bit);
            }
            for m in &mut y_ge[..=yr] {
                set(m, bit);
            }
        }
        Pattern {
            n,
            x_ge,
            y_ge,
            counted,
        }
    }

    /// Samples per receiver.
    fn count(&self) -> usize {
        self.n * self.n
    }

    /// The full mask (every sample set).
    fn all(&self) -> Mask<W> {
        self.x_ge[0]
    }

    /// The rank bounds for a micro-patch at d = wO - wR from its receiver.
    #[inline(always)]
    fn bounds(&self, d: f32) -> RankBounds {
        // For d <= 0 (inv = 0) every bound is S/2 - 1/2: an empty range.
        self.scaled(if d > 0.0 { 1.0 / d } else { 0.0 })
    }

    /// Rank bounds of light coordinates already divided by d (inv = 1).
    #[inline(always)]
    fn scaled(&self, inv: f32) -> RankBounds {
        let s = self.count() as f32;
        RankBounds {
            inv,
            half: 0.5 * s,
            s,
        }
    }

    /// The samples whose x-rank is in [ka, kb). No branch on empty ranges:
    /// with kb <= ka, x_ge[ka] is a subset of x_ge[kb] and the band is empty
    /// anyway (and the branch mispredicts).
    #[inline(always)]
    fn x_band(&self, ka: u16, kb: u16) -> Mask<W> {
        and_not(rank(&self.x_ge, ka), rank(&self.x_ge, kb))
    }

    #[inline(always)]
    fn y_band(&self, kc: u16, kd: u16) -> Mask<W> {
        and_not(rank(&self.y_ge, kc), rank(&self.y_ge, kd))
    }
}

/// `table[k]` for a rank k that `RankBounds::lo`/`hi` clamped to [0, S]:
/// the tables hold S + 1 entries, so the index is always in range, and the
/// bounds check (a compare and branch per lookup, 4 per lane and micro-patch:
/// profiled at a tenth of the kernel) is left out.
#[inline(always)]
fn rank<const W: usize>(table: &[Mask<W>], k: u16) -> &Mask<W> {
    debug_assert!((k as usize) < table.len());
    // SAFETY: every rank comes from RankBounds::lo or hi, clamped to
    // [0, S] = [0, table.len() - 1] (Pattern::new makes S + 1 entries).
    unsafe { table.get_unchecked(k as usize) }
}

// Explicit loops, not `std::array::from_fn`: the kernels are compiled with
// AVX2 / AVX-512 enabled (gather/simd.rs), and from_fn's closure was not
// inlined into them (profiled: a third of the time in `try_from_fn`, and
// libm calls for ceil and floor outside the vector code).
#[inline(always)]
fn and<const W: usize>(a: Mask<W>, b: Mask<W>) -> Mask<W> {
    let mut m = [0u64; W];
    for q in 0..W {
        m[q] = a[q] & b[q];
    }
    m
}

#[inline(always)]
fn and_not<const W: usize>(a: &Mask<W>, b: &Mask<W>) -> Mask<W> {
    let mut m = [0u64; W];
    for q in 0..W {
        m[q] = a[q] & !b[q];
    }
    m
}

/// Light coordinate t in [-1, 1] (half-light units relative to the
/// receiver, before scaling by 1/d) -> sample ranks.
struct RankBounds {
    inv: f32,
    half: f32,
    s: f32,
}

impl RankBounds {
    /// t -> sample units (t / d + 1) S/2 - 1/2.
    #[inline(always)]
    fn to(&self, t: f32) -> f32 {
        (t * self.inv + 1.0) * self.half - 0.5
    }

    /// The first rank at or above lower bound t, clamped to [0, S].
    #[inline(always)]
    fn lo(&self, t: f32) -> u16 {
        self.index(self.to(t).ceil())
    }

    /// One past the last rank at or below upper bound t, clamped to [0, S].
    #[inline(always)]
    fn hi(&self, t: f32) -> u16 {
        self.index(self.to(t).floor() + 1.0)
    }

    /// A whole rank clamped to [0, S], NaN to 0 (as `clamp(0, S) as u16`
    /// gives), in a form that vectorizes: `as u16` saturates lane by lane,
    /// and kept the tile path's rank arithmetic scalar (profiled at half of
    /// the whole-tile kernel).
    #[inline(always)]
    fn index(&self, k: f32) -> u16 {
        let k = gather::min(gather::max(k, 0.0), self.s);
        // SAFETY: k is finite and in [0, S] (max maps NaN to 0), S <= 1024.
        unsafe { k.to_int_unchecked::<i32>() as u16 }
    }
}

/// 1/(wc - wR) for a quad corner at 1/depth wc seen from a receiver at wR,
/// given d = w - wR of the quad's centre: 0 when the centre is not in front
/// of the receiver (the quad then covers nothing: every bound is the empty
/// range), the centre's 1/d for a corner at or behind the receiver (the
/// quad is not stretched toward the receiver's own depth).
#[inline(always)]
fn corner_inv(wc: f32, wr: f32, d: f32) -> f32 {
    let dc = wc - wr;
    if d > 0.0 {
        1.0 / if dc > 0.0 { dc } else { d }
    } else {
        0.0
    }
}

/// The bounding interval of a quad's projected corners along one axis: the
/// corners' coordinates (relative to the receiver) times their 1/d.
#[inline(always)]
fn span(t: [f32; 4]) -> (f32, f32) {
    let lo = gather::min(gather::min(t[0], t[1]), gather::min(t[2], t[3]));
    let hi = gather::max(gather::max(t[0], t[1]), gather::max(t[2], t[3]));
    (lo, hi)
}

/// `span` for four columns (or rows) at once, one corner per argument.
/// `Vec4::min` and `max` are x86's minps and maxps, as `gather::min` and
/// `max`: the same bits.
#[inline(always)]
fn span_v(t0: Vec4, t1: Vec4, t2: Vec4, t3: Vec4) -> (Vec4, Vec4) {
    (t0.min(t1).min(t2.min(t3)), t0.max(t1).max(t2.max(t3)))
}

/// The accumulator: masks of W words, flat micro-patches or (QUADS) quads.
struct MaskKernel<'a, const W: usize, const QUADS: bool> {
    p: &'a Pattern<W>,
}

/// A group's masks, word-major: `m[q][l]` is word q of lane l's mask. A row
/// of a tile (TILE_W lanes) is then TILE_W contiguous words per q, which the
/// whole-tile path ORs with one word of the row's y-band broadcast (two AVX2
/// registers per word); lane-major masks made the compiler transpose every
/// row in and out of registers (profiled: 44% of the two spheres at 512²).
type Masks<const W: usize> = [[u64; LANES]; W];

/// Per-column x-bands or per-row y-bands of a tile, word-major as `Masks`.
type Bands<const W: usize> = [[u64; TILE_W]; W];
const _: () = assert!(TILE_W == ROWS_PER_GROUP);

impl<const W: usize, const QUADS: bool> MaskKernel<'_, W, QUADS> {
    /// ORs the sample rectangle of ranks [ka, kb) x [kc, kd) into lane l.
    #[inline(always)]
    fn mark(&self, m: &mut Masks<W>, l: usize, [ka, kb, kc, kd]: [u16; 4]) {
        let band = and(self.p.x_band(ka, kb), self.p.y_band(kc, kd));
        for q in 0..W {
            m[q][l] |= band[q];
        }
    }

    /// ORs a whole tile's rectangles given as rank ranges per column (x:
    /// [xa, xb)) and per row (y: [ya, yb)). The ranks come from arithmetic
    /// done for the 8 columns and 8 rows at once (so that it vectorizes); a
    /// micro-patch whose ranges are empty for every row marks nothing (the
    /// callers leave out one that is empty for every column before they
    /// compute its rows').
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // transposes: one index over two arrays
    fn mark_ranks(&self, acc: &mut Masks<W>, x: &Ranks, y: &Ranks) {
        if y.empty() {
            return;
        }
        let p = self.p;
        let (mut xb, mut yb) = ([[0u64; TILE_W]; W], [[0u64; TILE_W]; W]);
        for c in 0..TILE_W {
            let band = p.x_band(x.lo[c], x.hi[c]);
            for q in 0..W {
                xb[q][c] = band[q];
            }
        }
        for row in 0..ROWS_PER_GROUP {
            let band = p.y_band(y.lo[row], y.hi[row]);
            for q in 0..W {
                yb[q][row] = band[q];
            }
        }
        self.mark_tile(acc, &xb, &yb, y);
    }

    /// ORs the per-column x-bands and per-row y-bands of a whole tile.
    #[inline(always)]
    fn mark_tile(&self, acc: &mut Masks<W>, xb: &Bands<W>, yb: &Bands<W>, y: &Ranks) {
        for row in 0..ROWS_PER_GROUP {
            // A row of receivers the micro-patch misses (outside its reach in
            // y) takes no stores: common at the edges of a tile's reach.
            if y.lo[row] >= y.hi[row] {
                continue;
            }
            for q in 0..W {
                let yq = yb[q][row];
                let m = &mut acc[q][row * TILE_W..(row + 1) * TILE_W];
                for (m, x) in m.iter_mut().zip(&xb[q]) {
                    *m |= x & yq;
                }
            }
        }
    }
}

/// Rank ranges [lo, hi) for the 8 columns or the 8 rows of a tile.
struct Ranks {
    lo: [u16; TILE_W],
    hi: [u16; TILE_W],
}

impl Ranks {
    /// The ranges of the intervals [lo, hi] (sample units before rounding).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over three arrays
    fn new(b: &RankBounds, lo: &[f32; TILE_W], hi: &[f32; TILE_W]) -> Ranks {
        let mut r = Ranks {
            lo: [0; TILE_W],
            hi: [0; TILE_W],
        };
        for k in 0..TILE_W {
            r.lo[k] = b.lo(lo[k]);
            r.hi[k] = b.hi(hi[k]);
        }
        r
    }

    /// Whether every range is empty.
    #[inline(always)]
    fn empty(&self) -> bool {
        self.lo.iter().zip(&self.hi).all(|(a, b)| a >= b)
    }
}

impl<const W: usize, const QUADS: bool> Accumulator for MaskKernel<'_, W, QUADS> {
    type State = Masks<W>;
    const LAYERS_SHARE_STATE: bool = true;
    const CORNERS: bool = QUADS;

    fn empty(&self) -> Self::State {
        [[0; LANES]; W]
    }

    /// Ranks covered by the back-projection of [x0, x1] (half-light units
    /// relative to the receiver) scaled by r = 1/d: sample x = (rank + 1/2) / S
    /// on the light's [0, 1], so [a, b] holds ranks ceil(aS - 1/2) ..= floor(bS - 1/2).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over several lane arrays
    fn add_texel(&self, acc: &mut Self::State, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        let p = self.p;
        // Index arithmetic for all lanes first (vectorizes), lookups after.
        let mut k = [[0u16; 4]; LANES];
        for l in 0..LANES {
            let b = p.bounds(w - g.wr[l]);
            k[l] = [
                b.lo(x0 - r.xr[l]),
                b.hi(x1 - r.xr[l]),
                b.lo(-r.nay0[l]),
                b.hi(r.ay1[l]),
            ];
        }
        for (l, k) in k.iter().enumerate() {
            self.mark(acc, l, *k);
        }
    }

    /// One depth for the whole tile: the x-ranks depend on the column only
    /// and the y-ranks on the row only, so 8 + 8 bands replace 64 x 2
    /// (the same bits as `add_texel`).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over the ranks and the lanes
    fn add_texel_tile(
        &self,
        acc: &mut Self::State,
        w: f32,
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) -> bool {
        let b = self.p.bounds(w - g.wr[0]);
        let (mut xa, mut xb) = ([0f32; TILE_W], [0f32; TILE_W]);
        for c in 0..TILE_W {
            xa[c] = x0 - r.xr[c];
            xb[c] = x1 - r.xr[c];
        }
        // The rows' ranges only for a micro-patch that reaches a column.
        let x = Ranks::new(&b, &xa, &xb);
        if x.empty() {
            return false;
        }
        let (mut ya, mut yb) = ([0f32; TILE_W], [0f32; TILE_W]);
        for row in 0..ROWS_PER_GROUP {
            let l = row * TILE_W;
            ya[row] = -r.nay0[l];
            yb[row] = r.ay1[l];
        }
        self.mark_ranks(acc, &x, &Ranks::new(&b, &ya, &yb));
        true
    }

    /// The quad [x0, x1] x (row) with corner 1/depths `c` ([top-left,
    /// top-right, bottom-left, bottom-right]) and centre 1/depth w: the
    /// bounding rectangle of its four corners projected from each lane's
    /// receiver.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over several lane arrays
    fn add_quad(
        &self,
        acc: &mut Self::State,
        w: f32,
        c: &[f32; 4],
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) {
        let b = self.p.scaled(1.0);
        let mut k = [[0u16; 4]; LANES];
        for l in 0..LANES {
            let wr = g.wr[l];
            let d = w - wr;
            let i = [
                corner_inv(c[0], wr, d),
                corner_inv(c[1], wr, d),
                corner_inv(c[2], wr, d),
                corner_inv(c[3], wr, d),
            ];
            let (a, e) = (x0 - r.xr[l], x1 - r.xr[l]);
            let (bottom, top) = (-r.nay0[l], r.ay1[l]);
            let (xa, xb) = span([a * i[0], e * i[1], a * i[2], e * i[3]]);
            let (ya, yb) = span([top * i[0], top * i[1], bottom * i[2], bottom * i[3]]);
            k[l] = [b.lo(xa), b.hi(xb), b.lo(ya), b.hi(yb)];
        }
        for (l, k) in k.iter().enumerate() {
            self.mark(acc, l, *k);
        }
    }

    /// `add_quad` for a tile on one depth: the corners' 1/d are shared
    /// (`inv`, from `corner_invs`), the x-span depends on the column only and
    /// the y-span on the row only (the same bits).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over the spans and the lanes
    fn add_quad_tile(
        &self,
        acc: &mut Self::State,
        _w: f32,
        _c: &[f32; 4],
        inv: &[f32; 4],
        x0: f32,
        x1: f32,
        r: &RowLanes,
        _g: &Group,
    ) -> bool {
        let b = self.p.scaled(1.0);
        // The corners' projections per column, then per row, four columns
        // (rows) to a vector: written column by column, the compiler packed
        // them corner by corner and took the spans apart with a branch per
        // column (profiled: a fifth of the closed kernel on the floating
        // bunny).
        let i = inv.map(Vec4::splat);
        let (mut xa, mut xb) = ([0f32; TILE_W], [0f32; TILE_W]);
        for h in 0..TILE_W / 4 {
            let xr = Vec4::from_slice(&r.xr[4 * h..4 * h + 4]);
            let (a, e) = (Vec4::splat(x0) - xr, Vec4::splat(x1) - xr);
            let (lo, hi) = span_v(a * i[0], e * i[1], a * i[2], e * i[3]);
            lo.write_to_slice(&mut xa[4 * h..]);
            hi.write_to_slice(&mut xb[4 * h..]);
        }
        // The rows' spans only for a quad that reaches a column.
        let x = Ranks::new(&b, &xa, &xb);
        if x.empty() {
            return false;
        }
        let (mut ya, mut yb) = ([0f32; TILE_W], [0f32; TILE_W]);
        for h in 0..ROWS_PER_GROUP / 4 {
            let l = 4 * h * TILE_W;
            let top = Vec4::new(
                r.ay1[l],
                r.ay1[l + TILE_W],
                r.ay1[l + 2 * TILE_W],
                r.ay1[l + 3 * TILE_W],
            );
            let bottom = -Vec4::new(
                r.nay0[l],
                r.nay0[l + TILE_W],
                r.nay0[l + 2 * TILE_W],
                r.nay0[l + 3 * TILE_W],
            );
            let (lo, hi) = span_v(top * i[0], top * i[1], bottom * i[2], bottom * i[3]);
            lo.write_to_slice(&mut ya[4 * h..]);
            hi.write_to_slice(&mut yb[4 * h..]);
        }
        self.mark_ranks(acc, &x, &Ranks::new(&b, &ya, &yb));
        true
    }

    fn full(&self, acc: &Self::State, g: &Group) -> bool {
        let all = self.p.all();
        (0..LANES).all(|l| !g.wr[l].is_finite() || (0..W).all(|q| acc[q][l] == all[q]))
    }

    fn occlusion(&self, acc: &Self::State) -> Lanes {
        let s = self.p.counted as f32;
        let mut o = [0f32; LANES];
        for (l, o) in o.iter_mut().enumerate() {
            *o = (0..W).map(|q| acc[q][l].count_ones()).sum::<u32>() as f32 / s;
        }
        o
    }
}

impl Bitmask {
    /// The rank tables as the GPU twin (`gpu/bitmask.wgsl`) reads them: x_ge
    /// then y_ge, each entry 2 W u32 words (bit b of the mask is bit b % 32
    /// of word b / 32, as in the u64 words here).
    #[cfg(feature = "gpu")]
    pub(crate) fn rank_tables(&self) -> Vec<u32> {
        fn flat<const W: usize>(p: &Pattern<W>) -> Vec<u32> {
            p.x_ge
                .iter()
                .chain(&p.y_ge)
                .flat_map(|m| m.iter().flat_map(|w| [*w as u32, (*w >> 32) as u32]))
                .collect()
        }
        match &self.pattern {
            Patterns::Small(p) => flat(p),
            Patterns::Large(p) => flat(p),
        }
    }

    /// `samples` must be one of SAMPLE_COUNTS (checked by `Method::parse`).
    pub fn new(samples: u32, gaps: Gaps, hierarchy: Option<Hierarchy>) -> Bitmask {
        Bitmask::for_shape(samples, gaps, hierarchy, false)
    }

    /// `new`, for a disk light where `disk` (`Pattern::new`).
    pub fn for_shape(
        samples: u32,
        gaps: Gaps,
        hierarchy: Option<Hierarchy>,
        disk: bool,
    ) -> Bitmask {
        let n = (samples as f64).sqrt().round() as usize;
        let pattern = if n * n <= 256 {
            Patterns::Small(Pattern::new(n, disk))
        } else {
            Patterns::Large(Pattern::new(n, disk))
        };
        Bitmask {
            pattern,
            gaps,
            hierarchy,
            disk,
        }
    }

    /// The samples on the light: all of them, or a disk's.
    pub fn counted(&self) -> usize {
        match &self.pattern {
            Patterns::Small(p) => p.counted,
            Patterns::Large(p) => p.counted,
        }
    }

    /// The method for `inputs`' light: itself, or its pattern cut to the
    /// disk (built per call: a few milliseconds at 1024 samples).
    fn on(&self, inputs: &ShadowInputs) -> Option<Bitmask> {
        let disk = matches!(inputs.light_shape, LightShape::Disk { .. });
        (disk && !self.disk).then(|| {
            let n = match &self.pattern {
                Patterns::Small(p) => p.n,
                Patterns::Large(p) => p.n,
            };
            Bitmask::for_shape((n * n) as u32, self.gaps, self.hierarchy, true)
        })
    }
}

/// Calls `$f` with the accumulator for the method's pattern and gaps.
macro_rules! with_kernel {
    ($m:expr, |$k:ident| $body:expr) => {
        match (&$m.pattern, $m.gaps) {
            (Patterns::Small(p), Gaps::Closed) => {
                let $k = &MaskKernel::<4, true> { p };
                $body
            }
            (Patterns::Small(p), Gaps::Open) => {
                let $k = &MaskKernel::<4, false> { p };
                $body
            }
            (Patterns::Large(p), Gaps::Closed) => {
                let $k = &MaskKernel::<16, true> { p };
                $body
            }
            (Patterns::Large(p), Gaps::Open) => {
                let $k = &MaskKernel::<16, false> { p };
                $body
            }
        }
    };
}

// After `with_kernel!`, which it calls (macros are in scope from their
// definition on).
mod weighted;

/// The kernel a resolved `BitmaskConfig` runs (`kernel.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitmaskKernel {
    pub samples: u32,
    pub hierarchy: bool,
    pub gaps: Gaps,
}

impl Kernel for BitmaskKernel {
    const READS: &'static [Input] = &[Input::OccluderLayers];

    /// The gather maps of `ssm` (3), or for connected micro-quads their
    /// corner 1/depths and those corners' reciprocals from the receivers'
    /// common plane (4 each) besides, and the hierarchy's levels.
    fn maps_per_layer(&self) -> usize {
        let maps = if self.gaps == Gaps::Closed { 11 } else { 3 };
        maps_with_levels(maps, self.hierarchy)
    }

    fn visit_cost(&self) -> Option<f64> {
        Some(if self.samples > 256 {
            BITMASK_1024_VISIT
        } else {
            BITMASK_VISIT
        })
    }

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        Box::new(Bitmask::new(
            self.samples,
            self.gaps,
            self.hierarchy.then_some(HIERARCHY),
        ))
    }
}

impl ShadowMethod for Bitmask {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        if let Some(disk) = self.on(inputs) {
            return disk.visibility_map(inputs);
        }
        with_kernel!(self, |k| gather::visibility_map(k, inputs, self.hierarchy))
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        if let Some(disk) = self.on(inputs) {
            return disk.visibility_points(inputs, points);
        }
        with_kernel!(self, |k| gather::visibility_points(
            k,
            inputs,
            points,
            self.hierarchy
        ))
    }

    /// Weighted where asked for (`weighted.rs`): `gather::visibility_eye`.
    fn visibility_eye(
        &self,
        inputs: &ShadowInputs,
        eye: &EyePoints,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        gather::visibility_eye(
            inputs,
            eye,
            |p| self.visibility_points(inputs, p),
            |p, r| self.weighted_points(inputs, p, r),
        )
    }
}

/// Whether the hierarchy is on by default on the CPU: on for bitmask
/// (the level choice, `HIERARCHY`, is measured with it).
pub const HIERARCHY_DEFAULT_BITMASK: bool = true;

/// Micro-patches marking light samples in a bit mask per receiver
/// (Schwarz & Stamminger 2007).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitmaskConfig {
    /// One of `SAMPLE_COUNTS`.
    pub samples: u32,
    pub passes: Option<u32>,
    pub occluder_resolution: Option<(usize, usize)>,
    /// `None`: on where the backend has a hierarchy (the CPU), else off.
    pub hierarchy: Option<bool>,
    /// How neighbouring micro-patches meet.
    pub gaps: Gaps,
}

/// Light samples of `bitmask`: one of its patterns' sizes.
pub fn check_bitmask_samples(n: i64) -> Result<u32> {
    match SAMPLE_COUNTS.iter().find(|&&c| c as i64 == n) {
        Some(&c) => Ok(c),
        None => Err(Error::invalid(
            "samples",
            format!("bitmask takes one of {:?} samples, got {n}", SAMPLE_COUNTS),
        )),
    }
}

impl BitmaskConfig {
    pub fn new(
        samples: Option<i64>,
        passes: Option<i64>,
        occluder_resolution: Option<(i64, i64)>,
        hierarchy: Option<bool>,
        gaps: Option<&str>,
    ) -> Result<Self> {
        let gaps = match gaps {
            None => Gaps::default(),
            Some(g) => Gaps::parse(g).ok_or_else(|| {
                let names: Vec<&str> = Gaps::ALL.iter().map(|g| g.name()).collect();
                Error::invalid("gaps", format!("must be one of {names:?}, got {g:?}"))
            })?,
        };
        Ok(BitmaskConfig {
            gaps,
            samples: samples
                .map(check_bitmask_samples)
                .transpose()?
                .unwrap_or(DEFAULT_SAMPLES),
            passes: passes.map(check_passes).transpose()?,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
            hierarchy,
        })
    }
}

impl Default for BitmaskConfig {
    fn default() -> Self {
        BitmaskConfig {
            samples: DEFAULT_SAMPLES,
            passes: None,
            occluder_resolution: None,
            hierarchy: None,
            gaps: Default::default(),
        }
    }
}

impl KeywordForm for BitmaskConfig {
    fn from_keywords(k: &Keywords) -> Result<Self> {
        BitmaskConfig::new(
            k.int("samples")?,
            k.int("passes")?,
            k.resolution("occluder_resolution")?,
            k.bool("hierarchy")?,
            k.str("gaps")?,
        )
    }
    fn keywords(&self) -> Vec<(&'static str, Value)> {
        vec![
            ("samples", count(Some(self.samples))),
            ("passes", count(self.passes)),
            ("occluder_resolution", resolution(self.occluder_resolution)),
            ("hierarchy", flag(self.hierarchy)),
            ("gaps", Value::Str(self.gaps.name())),
        ]
    }
}

impl MethodSpec for BitmaskConfig {
    const NAME: &'static str = "bitmask";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if o.precision.is_some() {
            return Err(refuse("precision", PRECISION_SSM_ONLY));
        }
        BitmaskConfig::new(
            o.samples,
            o.passes,
            o.occluder_resolution,
            o.hierarchy,
            None,
        )
    }
    type Resolved = Self;
    type Kernel = BitmaskKernel;
    fn kernel(&self) -> BitmaskKernel {
        BitmaskKernel {
            samples: self.samples,
            hierarchy: self.hierarchy.unwrap_or(HIERARCHY_DEFAULT_BITMASK),
            gaps: self.gaps,
        }
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        let c = self;
        let (passes, occ, hierarchy) = resolve_maps(
            c.passes,
            c.occluder_resolution,
            c.hierarchy,
            HIERARCHY_DEFAULT_BITMASK,
            ctx,
        )?;
        Ok(BitmaskConfig {
            samples: c.samples,
            gaps: c.gaps,
            passes: Some(passes),
            occluder_resolution: Some(occ),
            hierarchy: Some(hierarchy),
        })
    }
    fn passes(&self) -> u32 {
        self.passes.unwrap_or(DEFAULT_PASSES)
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "bitmask",
            config: "Bitmask",
            summary: "The same micro-patches marking the light samples they hide in a bit mask \
                      per receiver, merged by OR (Schwarz & Stamminger 2007)",
            // The kernel's (`Kernel::READS`).
            reads: BitmaskKernel::READS.to_vec(),
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "samples",
                    kind: Kind::OneOf(SAMPLE_COUNTS.iter().map(|&n| n as i64).collect()),
                    default: Value::Int(DEFAULT_SAMPLES as i64),
                    default_doc: "256",
                    doc: "light samples per receiver, a multi-jittered pattern shared by all \
                          receivers",
                    restricted_on: vec![],
                },
                passes_option(),
                occluder_resolution_option(),
                hierarchy_option(HIERARCHY_DEFAULT_BITMASK),
                OptionInfo {
                    name: "gaps",
                    kind: Kind::Choice(Gaps::ALL.iter().map(|g| g.name()).collect()),
                    default: Value::Str(Gaps::default().name()),
                    default_doc: "closed",
                    doc: "how neighbouring micro-patches meet: closed, connected micro-quads \
                          (no light between neighbours on one surface; a depth step steeper \
                          than 76° from the light's direction stays open); open, the flat \
                          per-texel micro-patches of the paper, whose gaps leak light (§4.1.2)",
                    restricted_on: vec![],
                },
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;

    #[test]
    fn pattern_is_multi_jittered() {
        for n in [4, 8, 16] {
            check_pattern(Pattern::<4>::new(n, false));
        }
        check_pattern(Pattern::<16>::new(32, false));
    }

    fn check_pattern<const W: usize>(p: Pattern<W>) {
        let n = p.n;
        {
            let s = n * n;
            let pop = |m: &Mask<W>| m.iter().map(|w| w.count_ones()).sum::<u32>() as usize;
            // Prefix masks shrink by exactly one sample per rank.
            for k in 0..=s {
                assert_eq!(pop(&p.x_ge[k]), s - k);
                assert_eq!(pop(&p.y_ge[k]), s - k);
            }
            // One sample per coarse cell: the x-ranks of cell column i are i n..(i+1) n.
            for i in 0..n {
                let col: Mask<W> = {
                    let mut m = [0; W];
                    for j in 0..n {
                        set(&mut m, j * n + i);
                    }
                    m
                };
                let band: Mask<W> =
                    std::array::from_fn(|q| p.x_ge[i * n][q] & !p.x_ge[(i + 1) * n][q]);
                assert_eq!(band, col);
            }
        }
    }

    #[test]
    fn a_flat_plate_matches_the_closed_form_to_the_pattern_resolution() {
        // One plate, one depth: the union of its micro-patches is its
        // back-projection, and the pattern places each of its 4 edges to one
        // fine stratum: 4 x 16 samples of 256 in the worst case (a stratum's
        // samples lie in one coarse row or column).
        let max = crate::methods::plate_case::max_error(&Bitmask::new(256, Gaps::Open, None), 48);
        assert!(max <= 4.0 * 16.0 / 256.0 + 1e-6, "max error {max}");
    }

    #[test]
    fn a_disk_takes_the_samples_inside_it_and_matches_its_closed_form() {
        // 201 of 256 samples on the inscribed disk (pi/4 of 256 is 201.1),
        // 804 of 1024 (804.2).
        assert_eq!(
            Bitmask::for_shape(256, Gaps::Open, None, true).counted(),
            201
        );
        assert_eq!(
            Bitmask::for_shape(1024, Gaps::Open, None, false).counted(),
            1024
        );
        assert_eq!(
            Bitmask::for_shape(1024, Gaps::Open, None, true).counted(),
            804
        );
        // The plate under a disk of radius 1/2: the rim is placed to within
        // a sample's cell, so the error is larger than the square's but
        // small on average.
        let disk = LightShape::disk(0.5);
        for samples in [256, 1024] {
            let (mean, max) = crate::methods::plate_case::mean_and_max_error(
                &Bitmask::new(samples, Gaps::Open, None),
                48,
                disk,
            );
            assert!(
                mean < 0.01 && max < 0.08,
                "{samples}: mean {mean} max {max}"
            );
        }
        // The same maps under the square light are shaded as before.
        let square =
            crate::methods::plate_case::max_error(&Bitmask::new(256, Gaps::Open, None), 48);
        assert!(square <= 4.0 * 16.0 / 256.0 + 1e-6);
    }

    #[test]
    fn whole_tiles_on_one_depth_give_the_bits_of_the_per_lane_path() {
        // The map shades whole 8x8 tiles of a flat receiver per column and
        // per row; points (never tiles) take the per-lane path.
        let mut seed = 3u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let grid = MapGrid::new(37, 26, [0.4, 0.3]).unwrap();
        let front: Vec<f32> = (0..grid.len())
            .map(|_| {
                if rnd() < 0.4 {
                    (2.0 + rnd()) as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver = vec![3.7f32; grid.len()];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 0.7]),
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let pts: Vec<LightPoint> = (0..grid.len())
            .map(|k| LightPoint {
                x: grid.x_of(k % grid.width) as f32,
                y: grid.y_of(k / grid.width) as f32,
                z: receiver[k],
            })
            .collect();
        for samples in SAMPLE_COUNTS {
            for gaps in Gaps::ALL {
                let m = Bitmask::new(samples, gaps, None);
                let map = m.visibility_map(&inputs);
                assert!(map.iter().any(|&v| v > 0.0 && v < 1.0));
                let pts = m.visibility_points(&inputs, &pts);
                assert_eq!(map, pts, "{samples} samples, {gaps:?}");
            }
        }
    }

    #[test]
    fn overlapping_layers_count_once() {
        // The same plate in both layers: the SSM's max and the bitmask's OR
        // agree, and a plate covering everything gives visibility 0, not < 0.
        let grid = MapGrid::new(8, 8, [0.5, 0.5]).unwrap();
        let front = vec![2.0f32; 64];
        let receiver = vec![4.0f32; 64];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([0.1, 0.1]),
            receiver: &receiver,
            occluder_layers: vec![&front, &front],
            occluder_triangles: None,
        };
        for gaps in Gaps::ALL {
            let v = Bitmask::new(64, gaps, None).visibility_map(&inputs);
            assert!(v.iter().all(|&x| x == 0.0), "{v:?}");
        }
    }
}
