//! The gather traversal shared by the occluder-map methods (`ssm`, `bitmask`).
//!
//! Groups of LANES receivers (an 8x8 tile of the output map, or 64
//! neighbouring sample points) visit the occluder texels inside the union of
//! their possible extents: a micro-patch at 1/depth w reaches receivers within
//! (L/2)(w - wR) in tangent units (§3.3 of Atty et al. 2005), so occluder rows
//! and BLOCK-wide runs of them, which carry their nearest depth, bound what
//! can reach. What a pair contributes is the method's (an `Accumulator`).
//! The lanes are receivers, so the inner loop over occluder texels is long and
//! branch-free; bands of output rows are split across threads without locks.
//! The same source is compiled for AVX-512, AVX2+FMA and the baseline and
//! picked at run time.
//!
//! Here: the interface the methods implement and call (`Accumulator`,
//! `RowLanes`, the lane and tile sizes, `visibility_map`,
//! `visibility_points`) and the `Kernel` they share. `group.rs`: groups of
//! receivers and the per-group loops; `hierarchy.rs`: the occluder pyramid
//! (built in `Kernel::new`) and the level choice; `traverse.rs`: the
//! traversal over occluder texels for one group; `simd.rs`: the runtime
//! dispatch.

pub mod corners;
mod group;
mod hierarchy;
mod simd;
mod traverse;

pub(super) use group::Group;
pub use hierarchy::Hierarchy;
use hierarchy::Level;

use super::{LightPoint, ShadowInputs};
use crate::geom::light::MapGrid;
use rayon::prelude::*;

/// What a gather method does with one (occluder texel, receiver lanes) pair,
/// and how its per-lane state becomes an occlusion.
pub(super) trait Accumulator: Sync {
    /// Per-lane state (a sum, a bit mask).
    type State;
    /// Whether the occluder layers add into one state (bit masks: merged by
    /// OR) rather than each into its own (sums: merged by max).
    const LAYERS_SHARE_STATE: bool;
    fn empty(&self) -> Self::State;
    /// Adds the micro-patch [x0, x1] x (row) at 1/depth w to every lane.
    /// x0, x1 and the row's lanes are in half-light units (see RowLanes).
    fn add_texel(&self, acc: &mut Self::State, w: f32, x0: f32, x1: f32, row: &RowLanes, g: &Group);
    /// Whether every lane with a receiver is fully occluded (no more work).
    fn full(&self, acc: &Self::State, g: &Group) -> bool;
    /// Occlusion per lane in [0, 1].
    fn occlusion(&self, acc: &Self::State) -> Lanes;
    /// Whether occluder rows are visited top to bottom, the order in which
    /// the paper's GPU blended micro-patches (what FP16 emulation needs),
    /// rather than outward from the tile (what reaches umbra soonest).
    const ROW_MAJOR: bool = false;
    /// Called (with ROW_MAJOR) where the rows pass from one batch of about
    /// sqrt(M) micro-patches to the next (see `Layer::row_batch`).
    fn end_batch(&self, _acc: &mut Self::State) {}
    /// Called after each occluder row a group shades (before `full`).
    fn end_row(&self, _acc: &mut Self::State) {}
    /// `add_texel` for a group that is a whole tile (lane l = row TILE_W +
    /// column) whose receivers share one depth, as on a floor facing the
    /// light: lanes in a column then share x, lanes in a row share y, and a
    /// method may work per column and per row instead of per lane. Must give
    /// the same bits as `add_texel`.
    #[inline(always)]
    fn add_texel_tile(
        &self,
        acc: &mut Self::State,
        w: f32,
        x0: f32,
        x1: f32,
        row: &RowLanes,
        g: &Group,
    ) {
        self.add_texel(acc, w, x0, x1, row, g)
    }
    /// Whether the micro-patches are connected quads (`corners.rs`): the
    /// traversal then calls `add_quad` with each texel's corner 1/depths
    /// instead of `add_texel`.
    const CORNERS: bool = false;
    /// Adds the quad [x0, x1] x (row) at centre 1/depth w with corner
    /// 1/depths `c` ([top-left, top-right, bottom-left, bottom-right]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add_quad(
        &self,
        acc: &mut Self::State,
        w: f32,
        _c: &[f32; 4],
        x0: f32,
        x1: f32,
        row: &RowLanes,
        g: &Group,
    ) {
        self.add_texel(acc, w, x0, x1, row, g)
    }
    /// `add_quad` for a whole tile on one depth (as `add_texel_tile`), with
    /// the corners' `corners::corner_invs` for the tile's receiver depth.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add_quad_tile(
        &self,
        acc: &mut Self::State,
        w: f32,
        c: &[f32; 4],
        _inv: &[f32; 4],
        x0: f32,
        x1: f32,
        row: &RowLanes,
        g: &Group,
    ) {
        self.add_quad(acc, w, c, x0, x1, row, g)
    }
}

/// Per-lane receiver coordinates for one occluder row, in half-light units
/// (2x / Lx, 2y / Ly): the receiver's x, and the row's y-interval relative to
/// the receiver as [-nay0, ay1].
pub(super) struct RowLanes {
    pub xr: Lanes,
    pub nay0: Lanes,
    pub ay1: Lanes,
}

/// Receivers per group (vector lanes: 4 AVX-512 registers). Fixed in the
/// source, so the summation order (and the result) does not depend on the
/// SIMD width the CPU offers. A power of two.
pub(super) const LANES: usize = 64;
const _: () = assert!(LANES.is_power_of_two());
/// Map texels are shaded in square tiles of TILE_W x ROWS_PER_GROUP
/// receivers: one visit of an occluder row serves the whole tile, and a
/// square keeps the union of the receivers' extents small. (Measured on the
/// bunny at 256²: 8x8 beats 16x1 by 1.4x and 16x4 or 32x2 by 5-15%.)
pub(super) const TILE_W: usize = 8;
pub(super) const ROWS_PER_GROUP: usize = LANES / TILE_W;
/// Occluder texels per block for the block-level depth bound (8 measured
/// best: 16 costs 5% more, 32 15%).
const BLOCK: usize = 8;

pub(super) type Lanes = [f32; LANES];

/// min and max as x86's minps/maxps read them (the second operand wins on NaN,
/// and no NaN reaches them here): one instruction each, where f32::min's NaN
/// rules cost three.
#[inline(always)]
pub(super) fn min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

#[inline(always)]
pub(super) fn max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// Everything the per-group loop reads, prepared once per call.
struct Kernel {
    /// The output (receiver) grid: width, column and row centers.
    rec_width: usize,
    rec_col_x: Vec<f32>,
    rec_row_y: Vec<f32>,
    /// The occluder grid (level 0) from here on: half-extents and size.
    tx: f32,
    ty: f32,
    width: f32,
    height: f32,
    inv_half_lx: f32,
    inv_half_ly: f32,
    half_lx: f32,
    half_ly: f32,
    /// Level 0, then coarser ones when a hierarchy is used.
    levels: Vec<Level>,
    /// Largest level-0 texel size on the light, in half-light units, per
    /// unit of d = wO - wR; 0 without a hierarchy.
    texel_per_d: f32,
    /// 2 x the hierarchy's `max_texel_on_light` (half-light units).
    max_on_light: f32,
    /// The receiver 1/depth most whole tiles share (a floor facing the
    /// light), for which every layer holds its quads' corner reciprocals
    /// (`Layer::plane_invs`); None: none computed.
    plane_wr: Option<f32>,
}

/// Shades every receiver texel of the output map with accumulator `a`.
pub(super) fn visibility_map<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let mut k = Kernel::new(inputs, hierarchy, A::CORNERS);
    if A::CORNERS {
        k.set_plane(inputs.receiver);
    }
    let w = k.rec_width;
    let mut out = vec![1f32; inputs.grid.len()];
    out.par_chunks_mut(w * ROWS_PER_GROUP)
        .zip(inputs.receiver.par_chunks(w * ROWS_PER_GROUP))
        .enumerate()
        .for_each(|(t, (o, r))| k.shade_row(a, t * ROWS_PER_GROUP, r, o));
    out
}

/// The order `visibility_points` shades `points` in: sorted by the texel of
/// the occluder grid `og` each falls in, tile-major, so that each run of
/// LANES points (a group) forms a compact tile and its union of extents
/// stays small. The GPU twin (`gpu/eye.rs`) groups points by it too.
pub(crate) fn point_order(og: &MapGrid, points: &[LightPoint]) -> Vec<u32> {
    // Kernel::row_coord and col_coord at level 0 (scale 1).
    let (tx, ty) = (og.tx as f32, og.ty as f32);
    let (width, height) = (og.width as f32, og.height as f32);
    let key = |p: &LightPoint| {
        let j = ((1.0 - p.y / ty) * 0.5 * height - 0.5)
            .round()
            .clamp(0.0, height - 1.0) as u64;
        let i = ((p.x / tx + 1.0) * 0.5 * width - 0.5)
            .round()
            .clamp(0.0, width - 1.0) as u64;
        // Tile-major order, so that runs of LANES points form compact tiles.
        let (t, r) = (TILE_W as u64, ROWS_PER_GROUP as u64);
        let tiles_x = (og.width as u64).div_ceil(t);
        (((j / r) * tiles_x + i / t) * r + j % r) * t + i % t
    };
    // Each key computed once (evaluating it in every comparison cost more
    // than the shading), then the order of a stable sort by key: ties keep
    // the input order.
    let keys: Vec<u64> = points.par_iter().map(key).collect();
    let top = keys.iter().copied().max().unwrap_or(0);
    if top < 4 * points.len() as u64 + 1024 {
        // Keys are texel indices: a counting sort when they are few.
        let mut start = vec![0u32; top as usize + 2];
        for &k in &keys {
            start[k as usize + 1] += 1;
        }
        for b in 1..start.len() {
            start[b] += start[b - 1];
        }
        let mut order = vec![0u32; points.len()];
        for (n, &k) in keys.iter().enumerate() {
            order[start[k as usize] as usize] = n as u32;
            start[k as usize] += 1;
        }
        return order;
    }
    let mut keyed: Vec<(u64, u32)> = keys.into_iter().zip(0u32..).collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, n)| n).collect()
}

/// Points a group of `visibility_points` holds (the GPU twin's workgroup).
#[cfg(feature = "gpu")]
pub(crate) const POINTS_PER_GROUP: usize = LANES;

/// A group of up to LANES points as `visibility_points` shades it, for the
/// GPU twin: per lane x, y and 1/depth (+inf: no receiver), and the bounds
/// over the lanes with a receiver.
#[cfg(feature = "gpu")]
pub(crate) struct PointGroup {
    pub xr: Lanes,
    pub yr: Lanes,
    pub wr: Lanes,
    pub x_lo: f32,
    pub x_hi: f32,
    pub y_lo: f32,
    pub y_hi: f32,
    pub wr_min: f32,
}

/// The group of `pts` (at most LANES, in `point_order`), or None when no
/// point has a receiver in front of the light.
#[cfg(feature = "gpu")]
pub(crate) fn point_group(pts: &[LightPoint]) -> Option<PointGroup> {
    Group::new(pts.iter().map(|p| (p.x, p.y, p.z)), false).map(|g| PointGroup {
        xr: g.xr,
        yr: g.yr,
        wr: g.wr,
        x_lo: g.x_lo,
        x_hi: g.x_hi,
        y_lo: g.y_lo,
        y_hi: g.y_hi,
        wr_min: g.wr_min,
    })
}

/// Shades receiver points (light space) with accumulator `a`.
pub(super) fn visibility_points<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    points: &[LightPoint],
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let k = Kernel::new(inputs, hierarchy, A::CORNERS);
    // Shade neighbours together: sort the points by the texel they fall in,
    // so that each group's union of extents stays small.
    let order = point_order(&inputs.occluder_grid, points);
    let sorted: Vec<LightPoint> = order.iter().map(|&n| points[n as usize]).collect();
    let mut shaded = vec![1f32; points.len()];
    shaded
        .par_chunks_mut(LANES * 4)
        .zip(sorted.par_chunks(LANES * 4))
        .for_each(|(o, p)| k.shade_points(a, p, o));
    let mut out = vec![1f32; points.len()];
    for (&n, &v) in order.iter().zip(&shaded) {
        out[n as usize] = v;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `point_order` is the stable sort by texel key, on both of its paths
    /// (the counting sort of few keys, the sort of many).
    #[test]
    fn point_order_is_the_stable_sort_by_texel() {
        let mut seed = 7u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let points: Vec<LightPoint> = (0..3000)
            .map(|_| LightPoint {
                // Some beyond the map (clamped), many sharing a texel.
                x: (r() * 2.4 - 1.2) * 0.5,
                y: (r() * 2.4 - 1.2) * 0.5,
                z: 1.0,
            })
            .collect();
        for side in [16usize, 4096] {
            let og = MapGrid::new(side, side, [0.5, 0.5]).unwrap();
            let (w, h) = (side as f32, side as f32);
            let key = |p: &LightPoint| {
                let j = ((1.0 - p.y / 0.5) * 0.5 * h - 0.5)
                    .round()
                    .clamp(0.0, h - 1.0) as u64;
                let i = ((p.x / 0.5 + 1.0) * 0.5 * w - 0.5)
                    .round()
                    .clamp(0.0, w - 1.0) as u64;
                let (t, rr) = (TILE_W as u64, ROWS_PER_GROUP as u64);
                let tiles_x = (side as u64).div_ceil(t);
                (((j / rr) * tiles_x + i / t) * rr + j % rr) * t + i % t
            };
            let mut want: Vec<u32> = (0..points.len() as u32).collect();
            want.sort_by_key(|&n| key(&points[n as usize]));
            assert_eq!(point_order(&og, &points), want, "side {side}");
        }
    }
}
