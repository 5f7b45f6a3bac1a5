//! The gather kernel's data, apart from the code that runs it: the
//! interface a method implements (`Accumulator`), the lane and tile sizes,
//! the kernel prepared once per call (`Kernel`), the occluder pyramid's
//! levels and layers, and a group of receivers. `mod.rs` (the entry
//! points), `group.rs`, `hierarchy.rs`, `traverse.rs` and `simd.rs` each
//! implement part of the kernel on these types and read no one else's.

/// What a gather method does with one (occluder texel, receiver lanes) pair,
/// and how its per-lane state becomes an occlusion.
pub(in crate::methods) trait Accumulator: Sync {
    /// Per-lane state (a sum, a bit mask).
    type State;
    /// Whether the occluder layers add into one state (bit masks: merged by
    /// OR) rather than each into its own (sums: merged by max).
    const LAYERS_SHARE_STATE: bool;
    fn empty(&self) -> Self::State;
    /// `empty` for group `g` (each layer's state, where they do not share
    /// one): where the accumulator keeps what it knows of the group's
    /// points (`Group::first`) in the state, as the SSM's weighted shading.
    #[inline(always)]
    fn empty_at(&self, _g: &Group) -> Self::State {
        self.empty()
    }
    /// Adds the micro-patch [x0, x1] x (row) at 1/depth w to every lane.
    /// x0, x1 and the row's lanes are in half-light units (see RowLanes).
    fn add_texel(&self, acc: &mut Self::State, w: f32, x0: f32, x1: f32, row: &RowLanes, g: &Group);
    /// Whether every lane with a receiver is fully occluded (no more work).
    fn full(&self, acc: &Self::State, g: &Group) -> bool;
    /// Occlusion per lane in [0, 1].
    fn occlusion(&self, acc: &Self::State) -> Lanes;
    /// `occlusion` of a group's final state (the shared one, or each
    /// layer's in turn, back layer first), where the accumulator also reads
    /// what it knows of the group's points (`Group::first`): the bitmask's
    /// and the SSM's weighted shading do.
    #[inline(always)]
    fn occlusion_at(&self, acc: &Self::State, _g: &Group) -> Lanes {
        self.occlusion(acc)
    }
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
    /// the same bits as `add_texel`. Returns whether it did the work of a
    /// full visit, false where it found early that the micro-patch reaches
    /// no lane (what the visits' count charges: `meter.rs`).
    #[inline(always)]
    fn add_texel_tile(
        &self,
        acc: &mut Self::State,
        w: f32,
        x0: f32,
        x1: f32,
        row: &RowLanes,
        g: &Group,
    ) -> bool {
        self.add_texel(acc, w, x0, x1, row, g);
        true
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
    /// the corners' `corners::corner_invs` for the tile's receiver depth;
    /// returns as `add_texel_tile` does.
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
    ) -> bool {
        self.add_quad(acc, w, c, x0, x1, row, g);
        true
    }
}

/// Per-lane receiver coordinates for one occluder row, in half-light units
/// (2x / Lx, 2y / Ly): the receiver's x, and the row's y-interval relative to
/// the receiver as [-nay0, ay1].
pub(in crate::methods) struct RowLanes {
    pub xr: Lanes,
    pub nay0: Lanes,
    pub ay1: Lanes,
}

/// Receivers per group (vector lanes: 4 AVX-512 registers). Fixed in the
/// source, so the summation order (and the result) does not depend on the
/// SIMD width the CPU offers. A power of two.
pub(in crate::methods) const LANES: usize = 64;
const _: () = assert!(LANES.is_power_of_two());
/// Map texels are shaded in square tiles of TILE_W x ROWS_PER_GROUP
/// receivers: one visit of an occluder row serves the whole tile, and a
/// square keeps the union of the receivers' extents small. (Measured on the
/// bunny at 256²: 8x8 beats 16x1 by 1.4x and 16x4 or 32x2 by 5-15%.)
pub(in crate::methods) const TILE_W: usize = 8;
pub(in crate::methods) const ROWS_PER_GROUP: usize = LANES / TILE_W;
/// Occluder texels per block for the block-level depth bound (8 measured
/// best: 16 costs 5% more, 32 15%).
pub(super) const BLOCK: usize = 8;

pub(in crate::methods) type Lanes = [f32; LANES];

/// min and max as x86's minps/maxps read them (the second operand wins on NaN,
/// and no NaN reaches them here): one instruction each, where f32::min's NaN
/// rules cost three.
#[inline(always)]
pub(in crate::methods) fn min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

#[inline(always)]
pub(in crate::methods) fn max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// Everything the per-group loop reads, prepared once per call.
pub(super) struct Kernel {
    /// The output (receiver) grid: width, column and row centers.
    pub(super) rec_width: usize,
    pub(super) rec_col_x: Vec<f32>,
    pub(super) rec_row_y: Vec<f32>,
    /// The occluder grid (level 0) from here on: half-extents and size.
    pub(super) tx: f32,
    pub(super) ty: f32,
    pub(super) width: f32,
    pub(super) height: f32,
    pub(super) inv_half_lx: f32,
    pub(super) inv_half_ly: f32,
    pub(super) half_lx: f32,
    pub(super) half_ly: f32,
    /// Level 0, then coarser ones when a hierarchy is used.
    pub(super) levels: Vec<Level>,
    /// Largest level-0 texel size on the light, in half-light units, per
    /// unit of d = wO - wR; 0 without a hierarchy.
    pub(super) texel_per_d: f32,
    /// 2 x the hierarchy's `max_texel_on_light` (half-light units).
    pub(super) max_on_light: f32,
    /// The receiver 1/depth most whole tiles share (a floor facing the
    /// light), for which every layer holds its quads' corner reciprocals
    /// (`Layer::plane_invs`); None: none computed.
    pub(super) plane_wr: Option<f32>,
    /// The call's cancellation (`crate::cancel`), read where the kernel is
    /// made: a cancelled call's remaining groups are skipped.
    pub(super) stop: crate::cancel::Token,
    /// The visits' meter of the call (`work::metered`), read where the
    /// kernel is made: once past its limit, the remaining groups are skipped.
    pub(super) meter: Option<std::sync::Arc<super::meter::Meter>>,
}

/// Up to LANES receivers shaded together. Inactive lanes (no receiver) have
/// wr = +inf, which makes every contribution 0.
pub(in crate::methods) struct Group {
    pub xr: Lanes,
    pub yr: Lanes,
    pub wr: Lanes,
    /// Bounds over the active lanes.
    pub wr_min: f32,
    pub(super) wr_max: f32,
    /// A whole tile (lane l = row TILE_W + column, every lane active) whose
    /// receivers share one depth (see `Accumulator::add_texel_tile`).
    pub(super) uniform_tile: bool,
    pub(super) x_lo: f32,
    pub(super) x_hi: f32,
    pub(super) y_lo: f32,
    pub(super) y_hi: f32,
    /// For a run of points (`visibility_points`): the rank of lane 0's point
    /// in the order they are shaded in, so that lane l is point `first + l`
    /// of that order (what `Accumulator::occlusion_at` looks up per point);
    /// 0 for a tile of the output map.
    pub first: usize,
}

/// One occluder depth layer at one level of the hierarchy, in the form the
/// kernel reads.
pub(super) struct Layer {
    /// 1/depth per texel, 0 where empty (so it is never in front of a receiver).
    /// At coarser levels: the mean of the occupied children where at least
    /// half the children are occupied, else 0.
    pub(super) w: Vec<f32>,
    /// Smallest and largest 1/depth of the occupied level-0 texels under each
    /// texel (inf and 0 where none): what the level choice bounds with.
    pub(super) w_far: Vec<f32>,
    pub(super) w_near: Vec<f32>,
    /// Largest 1/depth of each BLOCK-wide block of each row (`blocks_per_row` a row).
    pub(super) block_w_max: Vec<f32>,
    pub(super) rows: Vec<RowSpan>,
    pub(super) w_max: f32,
    /// Batch of each row: runs of rows holding about sqrt(M) of the M
    /// occupied texels each (Appendix A's workaround for FP16 blending; the
    /// batches end at row boundaries here).
    pub(super) row_batch: Vec<u32>,
    /// Corner 1/depths of the connected micro-quads (`corners.rs`), when the
    /// method reads them; empty otherwise.
    pub(super) corners: Vec<[f32; 4]>,
    /// `corner_invs` of each quad seen from the kernel's `plane_wr` (empty
    /// without one): whole tiles on that plane read them instead of
    /// dividing per (quad, tile).
    pub(super) plane_invs: Vec<[f32; 4]>,
}

#[derive(Clone, Copy)]
pub(super) struct RowSpan {
    /// Largest 1/depth in the row (its nearest occluder texel).
    pub(super) w_max: f32,
    /// Occupied columns [first, last).
    pub(super) first: u32,
    pub(super) last: u32,
}

/// One level of the occluder hierarchy: its texel geometry and its layers.
/// Level 0 is the occluder grid; each next level halves both sizes
/// (rounding up), so texel i of level l covers level-0 columns
/// [i 2^l, (i + 1) 2^l).
pub(super) struct Level {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) blocks_per_row: usize,
    /// Level-0 texels per texel of this level, per axis (2^l).
    pub(super) scale: f32,
    /// Left edge (tangent x) of every column, and the left edge in
    /// half-light units (2 x0 / Lx).
    pub(super) col_x0: Vec<f32>,
    pub(super) col_x0_scaled: Vec<f32>,
    /// Center (tangent y) of every row.
    pub(super) row_y: Vec<f32>,
    /// Tangent half-size of a texel.
    pub(super) hw: f32,
    pub(super) hh: f32,
    pub(super) layers: Vec<Layer>,
}
