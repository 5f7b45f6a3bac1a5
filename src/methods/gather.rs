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

use super::{LightPoint, ShadowInputs};
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

/// One occluder depth layer at one level of the hierarchy, in the form the
/// kernel reads.
struct Layer {
    /// 1/depth per texel, 0 where empty (so it is never in front of a receiver).
    /// At coarser levels: the mean of the occupied children where at least
    /// half the children are occupied, else 0.
    w: Vec<f32>,
    /// Smallest and largest 1/depth of the occupied level-0 texels under each
    /// texel (inf and 0 where none): what the level choice bounds with.
    w_far: Vec<f32>,
    w_near: Vec<f32>,
    /// Largest 1/depth of each BLOCK-wide block of each row (`blocks_per_row` a row).
    block_w_max: Vec<f32>,
    rows: Vec<RowSpan>,
    w_max: f32,
    /// Batch of each row: runs of rows holding about sqrt(M) of the M
    /// occupied texels each (Appendix A's workaround for FP16 blending; the
    /// batches end at row boundaries here).
    row_batch: Vec<u32>,
}

#[derive(Clone, Copy)]
struct RowSpan {
    /// Largest 1/depth in the row (its nearest occluder texel).
    w_max: f32,
    /// Occupied columns [first, last).
    first: u32,
    last: u32,
}

impl Layer {
    /// Level 0: the occluder map as given.
    fn from_depth(depth: &[f32], width: usize) -> Layer {
        let w: Vec<f32> = depth
            .par_iter()
            .map(|&z| {
                if z.is_finite() && z > 0.0 {
                    1.0 / z
                } else {
                    0.0
                }
            })
            .collect();
        let w_far = w
            .iter()
            .map(|&x| if x > 0.0 { x } else { f32::INFINITY })
            .collect();
        let w_near = w.clone();
        Layer::new(w, w_far, w_near, width)
    }

    /// The next level: 2x2 texels become one (the last row or column of an
    /// odd size has fewer children). A coarse texel is occupied where most
    /// of its children are, so silhouettes neither grow nor shrink on
    /// average; its depth is the mean 1/depth of those children.
    fn downsample(&self, width: usize, height: usize) -> (Layer, usize, usize) {
        let (cw, ch) = (width.div_ceil(2), height.div_ceil(2));
        let mut w = vec![0f32; cw * ch];
        let mut w_far = vec![f32::INFINITY; cw * ch];
        let mut w_near = vec![0f32; cw * ch];
        for j in 0..ch {
            for i in 0..cw {
                let (mut n, mut occ, mut sum) = (0u32, 0u32, 0f32);
                let (mut far, mut near) = (f32::INFINITY, 0f32);
                for fj in 2 * j..(2 * j + 2).min(height) {
                    for fi in 2 * i..(2 * i + 2).min(width) {
                        let k = fj * width + fi;
                        n += 1;
                        if self.w[k] > 0.0 {
                            occ += 1;
                            sum += self.w[k];
                        }
                        far = far.min(self.w_far[k]);
                        near = near.max(self.w_near[k]);
                    }
                }
                let k = j * cw + i;
                // Ties (2 of 4) alternate in a checkerboard: always counting
                // them occupied grew silhouettes (measured: shadows 0.4%
                // darker on average per level).
                let tie_wins = (i + j) % 2 == 0;
                if occ > 0 && (2 * occ > n || (2 * occ == n && tie_wins)) {
                    w[k] = sum / occ as f32;
                }
                w_far[k] = far;
                w_near[k] = near;
            }
        }
        (Layer::new(w, w_far, w_near, cw), cw, ch)
    }

    fn new(w: Vec<f32>, w_far: Vec<f32>, w_near: Vec<f32>, width: usize) -> Layer {
        let block_w_max = w
            .par_chunks(width)
            .flat_map_iter(|row| {
                row.chunks(BLOCK)
                    .map(|b| b.iter().fold(0f32, |m, &x| m.max(x)))
            })
            .collect();
        let rows: Vec<RowSpan> = w
            .par_chunks(width)
            .map(|row| match row.iter().position(|&x| x > 0.0) {
                None => RowSpan {
                    w_max: 0.0,
                    first: 0,
                    last: 0,
                },
                Some(f) => {
                    let l = row.iter().rposition(|&x| x > 0.0).unwrap() + 1;
                    RowSpan {
                        w_max: row[f..l].iter().fold(0f32, |m, &x| m.max(x)),
                        first: f as u32,
                        last: l as u32,
                    }
                }
            })
            .collect();
        let w_max = rows.iter().fold(0f32, |m, r| m.max(r.w_max));
        let occupied: Vec<usize> = w
            .chunks(width)
            .map(|row| row.iter().filter(|&&x| x > 0.0).count())
            .collect();
        let m: usize = occupied.iter().sum();
        let per_batch = m.div_ceil(((m as f64).sqrt() as usize).max(1)).max(1);
        let mut before = 0;
        let row_batch = occupied
            .iter()
            .map(|&n| {
                let b = (before / per_batch) as u32;
                before += n;
                b
            })
            .collect();
        Layer {
            row_batch,
            w,
            w_far,
            w_near,
            block_w_max,
            rows,
            w_max,
        }
    }
}

/// Up to LANES receivers shaded together. Inactive lanes (no receiver) have
/// wr = +inf, which makes every contribution 0.
pub(super) struct Group {
    pub xr: Lanes,
    pub yr: Lanes,
    pub wr: Lanes,
    /// Bounds over the active lanes.
    pub wr_min: f32,
    wr_max: f32,
    /// A whole tile (lane l = row TILE_W + column, every lane active) whose
    /// receivers share one depth (see `Accumulator::add_texel_tile`).
    uniform_tile: bool,
    x_lo: f32,
    x_hi: f32,
    y_lo: f32,
    y_hi: f32,
}

impl Group {
    /// `None` when no lane has a receiver in front of the light. `tile`:
    /// the points are a whole tile of the output grid, row by row.
    fn new(pts: impl Iterator<Item = (f32, f32, f32)>, tile: bool) -> Option<Group> {
        let mut g = Group {
            xr: [0.0; LANES],
            yr: [0.0; LANES],
            wr: [f32::INFINITY; LANES],
            wr_min: f32::INFINITY,
            wr_max: 0.0,
            uniform_tile: false,
            x_lo: f32::INFINITY,
            x_hi: f32::NEG_INFINITY,
            y_lo: f32::INFINITY,
            y_hi: f32::NEG_INFINITY,
        };
        for (l, (x, y, z)) in pts.take(LANES).enumerate() {
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let wr = 1.0 / z;
            g.xr[l] = x;
            g.yr[l] = y;
            g.wr[l] = wr;
            g.wr_min = g.wr_min.min(wr);
            g.wr_max = g.wr_max.max(wr);
            g.x_lo = g.x_lo.min(x);
            g.x_hi = g.x_hi.max(x);
            g.y_lo = g.y_lo.min(y);
            g.y_hi = g.y_hi.max(y);
        }
        let first = g.wr[0].to_bits();
        g.uniform_tile = tile && g.wr[0].is_finite() && g.wr.iter().all(|w| w.to_bits() == first);
        g.wr_min.is_finite().then_some(g)
    }
}

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

/// One level of the occluder hierarchy: its texel geometry and its layers.
/// Level 0 is the occluder grid; each next level halves both sizes
/// (rounding up), so texel i of level l covers level-0 columns
/// [i 2^l, (i + 1) 2^l).
struct Level {
    width: usize,
    height: usize,
    blocks_per_row: usize,
    /// Level-0 texels per texel of this level, per axis (2^l).
    scale: f32,
    /// Left edge (tangent x) of every column, and the left edge in
    /// half-light units (2 x0 / Lx).
    col_x0: Vec<f32>,
    col_x0_scaled: Vec<f32>,
    /// Center (tangent y) of every row.
    row_y: Vec<f32>,
    /// Tangent half-size of a texel.
    hw: f32,
    hh: f32,
    layers: Vec<Layer>,
}

/// The level whose texels the level choice reads (8x8 level-0 texels each):
/// coarse enough that the search is cheap next to the shading, fine enough
/// that its distance bounds are tight.
const QUERY_LEVEL: usize = 3;
/// Levels stop when a map is this small.
const COARSEST_SIZE: usize = 4;

/// How the hierarchy picks a level for a tile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hierarchy {
    /// The largest back-projection of one texel onto the light a level may
    /// have, as a fraction of the light's width (and height), for the
    /// nearest occluder that can reach the tile.
    pub max_texel_on_light: f32,
}

/// Whether two depth maps hold the same bits.
fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
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
}

impl Kernel {
    fn new(inputs: &ShadowInputs, hierarchy: Option<Hierarchy>) -> Kernel {
        // Occluder texels live on the occluder grid; receivers on the output grid.
        let g = &inputs.occluder_grid;
        let r = &inputs.grid;
        let (hw, hh) = g.half_texel();
        let [lx, ly] = inputs.light_size;
        // A layer equal to one already kept changes nothing (sums merge by
        // max, masks by OR), so it is not shaded: single-sided or flat
        // occluders make the back map equal the front one, and such a scene
        // then costs one pass whatever `passes` says.
        let distinct: Vec<&[f32]> = inputs
            .occluder_layers
            .iter()
            .enumerate()
            .filter(|&(i, d)| !inputs.occluder_layers[..i].iter().any(|e| same_bits(e, d)))
            .map(|(_, d)| *d)
            .collect();
        let mut layers: Vec<Layer> = distinct
            .iter()
            .map(|d| Layer::from_depth(d, g.width))
            .collect();
        let mut levels = vec![];
        let (mut width, mut height) = (g.width, g.height);
        loop {
            let f = (1usize << levels.len()) as f64;
            let next = hierarchy.is_some() && width.max(height) > COARSEST_SIZE;
            let coarser: Vec<(Layer, usize, usize)> = if next {
                layers.iter().map(|l| l.downsample(width, height)).collect()
            } else {
                vec![]
            };
            // Level 0 keeps the grid's own arithmetic (the same bits as
            // without a hierarchy); coarser levels follow the same formulas.
            let col_x0: Vec<f32> = (0..width)
                .map(|i| {
                    if levels.is_empty() {
                        (g.x_of(i) - hw) as f32
                    } else {
                        (g.tx * (2.0 * i as f64 * f / g.width as f64 - 1.0)) as f32
                    }
                })
                .collect();
            let row_y: Vec<f32> = (0..height)
                .map(|j| {
                    if levels.is_empty() {
                        g.y_of(j) as f32
                    } else {
                        (g.ty * (1.0 - (2 * j + 1) as f64 * f / g.height as f64)) as f32
                    }
                })
                .collect();
            levels.push(Level {
                width,
                height,
                blocks_per_row: width.div_ceil(BLOCK),
                scale: f as f32,
                col_x0_scaled: col_x0
                    .iter()
                    .map(|&x| (x as f64 * 2.0 / lx) as f32)
                    .collect(),
                col_x0,
                row_y,
                hw: (hw * f) as f32,
                hh: (hh * f) as f32,
                layers,
            });
            if !next {
                break;
            }
            (width, height) = (coarser[0].1, coarser[0].2);
            layers = coarser.into_iter().map(|c| c.0).collect();
        }
        Kernel {
            rec_width: r.width,
            rec_col_x: (0..r.width).map(|i| r.x_of(i) as f32).collect(),
            rec_row_y: (0..r.height).map(|j| r.y_of(j) as f32).collect(),
            tx: g.tx as f32,
            ty: g.ty as f32,
            width: g.width as f32,
            height: g.height as f32,
            inv_half_lx: (2.0 / lx) as f32,
            inv_half_ly: (2.0 / ly) as f32,
            half_lx: (0.5 * lx) as f32,
            half_ly: (0.5 * ly) as f32,
            levels,
            texel_per_d: (4.0 * (hw / lx).max(hh / ly)) as f32,
            max_on_light: 2.0 * hierarchy.map_or(0.0, |h| h.max_texel_on_light),
        }
    }

    /// Continuous row coordinate of tangent y at level `lv`, in units where
    /// row j's center is j.
    #[inline(always)]
    fn row_coord(&self, lv: &Level, y: f32) -> f32 {
        ((1.0 - y / self.ty) * 0.5 * self.height) / lv.scale - 0.5
    }

    #[inline(always)]
    fn col_coord(&self, lv: &Level, x: f32) -> f32 {
        ((x / self.tx + 1.0) * 0.5 * self.width) / lv.scale - 0.5
    }

    /// The level to shade layer `li` with for group `g`, or None when no
    /// texel of the layer can reach it. The level is the coarsest whose
    /// texels, back-projected onto the light from the nearest occluder that
    /// can reach the group (smallest d = wO - wR), stay within
    /// `max_texel_on_light`: wide penumbrae (large d) get coarse texels,
    /// contact shadows (small d) keep the finest. A lower bound on d comes
    /// from the query level: each texel's farthest occupied descendant, and
    /// how far it lies from the group (a micro-patch at d reaches only
    /// receivers within (L/2) d plus a texel).
    fn level_for(&self, li: usize, g: &Group) -> Option<usize> {
        let w_max = self.levels[0].layers[li].w_max;
        if w_max <= g.wr_min {
            return None;
        }
        if self.levels.len() == 1 {
            return Some(0);
        }
        let q = &self.levels[QUERY_LEVEL.min(self.levels.len() - 1)];
        let layer = &q.layers[li];
        let (hw0, hh0) = (self.levels[0].hw, self.levels[0].hh);
        let reach_x = q.hw + self.half_lx * (w_max - g.wr_min);
        let reach_y = q.hh + self.half_ly * (w_max - g.wr_min);
        let (rows, cols) = (q.height as isize - 1, q.width as isize - 1);
        let j_lo = (self.row_coord(q, g.y_hi + reach_y).floor() as isize).clamp(0, rows) as usize;
        let j_hi = (self.row_coord(q, g.y_lo - reach_y).ceil() as isize).clamp(0, rows) as usize;
        let i_lo = (self.col_coord(q, g.x_lo - reach_x).floor() as isize).clamp(0, cols) as usize;
        let i_hi = (self.col_coord(q, g.x_hi + reach_x).ceil() as isize).clamp(0, cols) as usize;
        let mut d_lo = f32::INFINITY;
        for j in j_lo..=j_hi {
            let yc = q.row_y[j];
            let dy = (g.y_lo - (yc + q.hh)).max(yc - q.hh - g.y_hi).max(0.0);
            for i in i_lo..=i_hi {
                let k = j * q.width + i;
                let dw = layer.w_near[k] - g.wr_min;
                let x0 = q.col_x0[i];
                let dx = (g.x_lo - (x0 + 2.0 * q.hw)).max(x0 - g.x_hi).max(0.0);
                if dw <= 0.0 || dx >= hw0 + self.half_lx * dw || dy >= hh0 + self.half_ly * dw {
                    continue;
                }
                let bound = (layer.w_far[k] - g.wr_max)
                    .max((dx - hw0) / self.half_lx)
                    .max((dy - hh0) / self.half_ly)
                    .max(0.0);
                d_lo = d_lo.min(bound);
            }
        }
        if d_lo == f32::INFINITY {
            return None;
        }
        // Texel size on the light at level l: 2^l texel_per_d / d.
        let ratio = self.max_on_light * d_lo / self.texel_per_d;
        let level = if ratio >= 1.0 {
            ratio.log2().floor() as usize
        } else {
            0
        };
        Some(level.min(self.levels.len() - 1))
    }

    /// Adds one layer's micro-patches to `acc` for each lane, visiting rows
    /// outward and stopping when every lane is fully occluded.
    #[inline(always)]
    fn add_layer<A: Accumulator>(&self, a: &A, acc: &mut A::State, li: usize, g: &Group) {
        let Some(level) = self.level_for(li, g) else {
            return;
        };
        let lv = &self.levels[level];
        let layer = &lv.layers[li];
        if layer.w_max <= g.wr_min {
            return;
        }
        let reach_y = lv.hh + self.half_ly * (layer.w_max - g.wr_min);
        let last = lv.height as isize - 1;
        let j_lo = (self.row_coord(lv, g.y_hi + reach_y).floor() as isize).clamp(0, last);
        let j_hi = (self.row_coord(lv, g.y_lo - reach_y).ceil() as isize).clamp(0, last);
        if A::ROW_MAJOR {
            for j in j_lo..=j_hi {
                let j = j as usize;
                if j as isize > j_lo && layer.row_batch[j] != layer.row_batch[j - 1] {
                    a.end_batch(acc);
                }
                if self.add_row(a, acc, lv, layer, j, g) {
                    a.end_row(acc);
                    if a.full(acc, g) {
                        return;
                    }
                }
            }
            return;
        }
        // Visit rows outward from the receivers' own rows: in umbra the sums
        // reach 1 soonest that way.
        let j_c = (self.row_coord(lv, 0.5 * (g.y_lo + g.y_hi)).round() as isize).clamp(j_lo, j_hi);
        let (mut up, mut down) = (j_c, j_c + 1);
        while up >= j_lo || down <= j_hi {
            let mut touched = false;
            for j in [up, down] {
                if j >= j_lo && j <= j_hi && self.add_row(a, acc, lv, layer, j as usize, g) {
                    a.end_row(acc);
                    touched = true;
                }
            }
            if touched && a.full(acc, g) {
                return;
            }
            up -= 1;
            down += 1;
        }
    }

    /// Adds occluder row j's micro-patches to every lane; false when the row
    /// cannot reach any lane.
    #[inline(always)]
    fn add_row<A: Accumulator>(
        &self,
        a: &A,
        acc: &mut A::State,
        lv: &Level,
        layer: &Layer,
        j: usize,
        g: &Group,
    ) -> bool {
        let span = layer.rows[j];
        if span.first >= span.last || span.w_max <= g.wr_min {
            return false;
        }
        let dw = span.w_max - g.wr_min;
        let yc = lv.row_y[j];
        let (hw, hh) = (lv.hw, lv.hh);
        let dy = (g.y_lo - yc).max(yc - g.y_hi).max(0.0);
        if dy >= hh + self.half_ly * dw {
            return false;
        }
        let reach_x = hw + self.half_lx * dw;
        let i_lo = (self.col_coord(lv, g.x_lo - reach_x).floor() as isize).max(span.first as isize);
        let i_hi =
            (self.col_coord(lv, g.x_hi + reach_x).ceil() as isize + 1).min(span.last as isize);
        if i_lo >= i_hi {
            return false;
        }
        // Per lane, in half-light units (2x / Lx, 2y / Ly) and relative to the
        // lane's receiver: its x, and the row's y-interval [y0 - yr, y1 - yr].
        let mut rl = RowLanes {
            xr: [0f32; LANES],
            nay0: [0f32; LANES],
            ay1: [0f32; LANES],
        };
        for l in 0..LANES {
            rl.xr[l] = g.xr[l] * self.inv_half_lx;
            rl.nay0[l] = (g.yr[l] - (yc - hh)) * self.inv_half_ly;
            rl.ay1[l] = (yc + hh - g.yr[l]) * self.inv_half_ly;
        }
        let wx = 2.0 * hw * self.inv_half_lx;
        let row = &layer.w[j * lv.width..(j + 1) * lv.width];
        let blocks = &layer.block_w_max[j * lv.blocks_per_row..(j + 1) * lv.blocks_per_row];
        let (i_lo, i_hi) = (i_lo as usize, i_hi as usize);
        // Trim the run to the first and last block whose nearest texel can
        // reach a lane; blocks in between are shaded whole (one long loop,
        // one branch per texel, rather than a loop per block).
        let reaches = |b: usize| {
            let bdw = blocks[b] - g.wr_min;
            let s = (b * BLOCK).max(i_lo);
            let e = ((b + 1) * BLOCK).min(i_hi);
            let gap = (g.x_lo - (lv.col_x0[e - 1] + 2.0 * hw)).max(lv.col_x0[s] - g.x_hi);
            bdw > 0.0 && gap < self.half_lx * bdw && dy < hh + self.half_ly * bdw
        };
        let (mut b_lo, mut b_hi) = (i_lo / BLOCK, i_hi.div_ceil(BLOCK));
        while b_lo < b_hi && !reaches(b_lo) {
            b_lo += 1;
        }
        while b_hi > b_lo && !reaches(b_hi - 1) {
            b_hi -= 1;
        }
        if b_lo == b_hi {
            return true;
        }
        let (s, e) = ((b_lo * BLOCK).max(i_lo), (b_hi * BLOCK).min(i_hi));
        let texels = row[s..e].iter().zip(&lv.col_x0_scaled[s..e]);
        // w <= wr_min: empty, or behind every lane's receiver.
        if g.uniform_tile {
            for (&w, &x0) in texels.filter(|(&w, _)| w > g.wr_min) {
                a.add_texel_tile(acc, w, x0, x0 + wx, &rl, g);
            }
        } else {
            for (&w, &x0) in texels.filter(|(&w, _)| w > g.wr_min) {
                a.add_texel(acc, w, x0, x0 + wx, &rl, g);
            }
        }
        true
    }

    /// Visibility per lane, the layers merged as the accumulator says.
    #[inline(always)]
    fn shade_group<A: Accumulator>(&self, a: &A, g: &Group) -> Lanes {
        let occ = if A::LAYERS_SHARE_STATE {
            let mut acc = a.empty();
            for li in (0..self.levels[0].layers.len()).rev() {
                self.add_layer(a, &mut acc, li, g);
                if a.full(&acc, g) {
                    break;
                }
            }
            a.occlusion(&acc)
        } else {
            // Separate sums merged by max (§3.5). Back layer first: it is the
            // cheaper one (farther, so its micro-patches reach less far) and, on
            // solid occluders, the one that reaches full occlusion in umbra (the
            // front layer leaves gaps on curved surfaces, §4.1.2), which makes
            // the other layer unnecessary. (Measured 5% faster on the bunny.)
            let mut occ = [0f32; LANES];
            for li in (0..self.levels[0].layers.len()).rev() {
                let mut acc = a.empty();
                self.add_layer(a, &mut acc, li, g);
                let o = a.occlusion(&acc);
                for l in 0..LANES {
                    occ[l] = occ[l].max(o[l]);
                }
                if occ.iter().all(|&o| o >= 1.0) {
                    break;
                }
            }
            occ
        };
        let mut v = [1f32; LANES];
        for l in 0..LANES {
            if g.wr[l].is_finite() {
                v[l] = 1.0 - occ[l];
            }
        }
        v
    }

    #[inline(always)]
    /// Shades output rows j0 and j0 + 1 (when present): each group is a tile
    /// of TILE_W columns by ROWS_PER_GROUP rows, so that a visit of an
    /// occluder row serves both output rows.
    fn shade_row_generic<A: Accumulator>(
        &self,
        a: &A,
        j0: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        let w = self.rec_width;
        let rows = receiver.len() / w;
        for c in (0..w).step_by(TILE_W) {
            let e = (c + TILE_W).min(w);
            let pts = (0..ROWS_PER_GROUP).flat_map(|r| {
                (0..TILE_W).map(move |k| {
                    let i = c + k;
                    if r < rows && i < e {
                        (
                            self.rec_col_x[i],
                            self.rec_row_y[j0 + r],
                            receiver[r * w + i],
                        )
                    } else {
                        (0.0, 0.0, f32::INFINITY)
                    }
                })
            });
            if let Some(g) = Group::new(pts, e - c == TILE_W && rows == ROWS_PER_GROUP) {
                let v = self.shade_group(a, &g);
                for r in 0..rows {
                    out[r * w + c..r * w + e].copy_from_slice(&v[r * TILE_W..r * TILE_W + (e - c)]);
                }
            }
        }
    }

    #[inline(always)]
    fn shade_points_generic<A: Accumulator>(&self, a: &A, pts: &[LightPoint], out: &mut [f32]) {
        for (o, p) in out.chunks_mut(LANES).zip(pts.chunks(LANES)) {
            if let Some(g) = Group::new(p.iter().map(|p| (p.x, p.y, p.z)), false) {
                let v = self.shade_group(a, &g);
                o.copy_from_slice(&v[..o.len()]);
            }
        }
    }
}

// Runtime dispatch: the same source compiled for AVX-512, AVX2+FMA or the
// baseline. The lanes are fixed in the source, so all three give the same bits.
impl Kernel {
    fn shade_row<A: Accumulator>(&self, a: &A, j: usize, receiver: &[f32], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_row_avx512(a, j, receiver, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_row_avx2(a, j, receiver, out) };
            }
        }
        self.shade_row_generic(a, j, receiver, out)
    }

    fn shade_points<A: Accumulator>(&self, a: &A, pts: &[LightPoint], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_points_avx512(a, pts, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_points_avx2(a, pts, out) };
            }
        }
        self.shade_points_generic(a, pts, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_row_avx512<A: Accumulator>(
        &self,
        a: &A,
        j: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        self.shade_row_generic(a, j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_row_avx2<A: Accumulator>(
        &self,
        a: &A,
        j: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        self.shade_row_generic(a, j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_points_avx512<A: Accumulator>(
        &self,
        a: &A,
        pts: &[LightPoint],
        out: &mut [f32],
    ) {
        self.shade_points_generic(a, pts, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_points_avx2<A: Accumulator>(&self, a: &A, pts: &[LightPoint], out: &mut [f32]) {
        self.shade_points_generic(a, pts, out)
    }
}

/// Shades every receiver texel of the output map with accumulator `a`.
pub(super) fn visibility_map<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let k = Kernel::new(inputs, hierarchy);
    let w = k.rec_width;
    let mut out = vec![1f32; inputs.grid.len()];
    out.par_chunks_mut(w * ROWS_PER_GROUP)
        .zip(inputs.receiver.par_chunks(w * ROWS_PER_GROUP))
        .enumerate()
        .for_each(|(t, (o, r))| k.shade_row(a, t * ROWS_PER_GROUP, r, o));
    out
}

/// Shades receiver points (light space) with accumulator `a`.
pub(super) fn visibility_points<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    points: &[LightPoint],
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let k = Kernel::new(inputs, hierarchy);
    // Shade neighbours together: sort the points by the texel they fall in,
    // so that each group's union of extents stays small.
    let key = |p: &LightPoint| {
        let lv = &k.levels[0];
        let j = k.row_coord(lv, p.y).round().clamp(0.0, k.height - 1.0) as u64;
        let i = k.col_coord(lv, p.x).round().clamp(0.0, k.width - 1.0) as u64;
        // Tile-major order, so that runs of LANES points form compact tiles.
        let (t, r) = (TILE_W as u64, ROWS_PER_GROUP as u64);
        let tiles_x = (lv.width as u64).div_ceil(t);
        (((j / r) * tiles_x + i / t) * r + j % r) * t + i % t
    };
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.par_sort_by_key(|&n| key(&points[n as usize]));
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
    use crate::light::MapGrid;

    /// Layers the kernel keeps for the occluder maps `layers`.
    fn kept(layers: Vec<&[f32]>) -> usize {
        let grid = MapGrid::new(8, 8, [0.5, 0.5]).unwrap();
        let receiver = vec![4.0f32; 64];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &receiver,
            occluder_layers: layers,
            occluder_triangles: None,
        };
        Kernel::new(&inputs, None).levels[0].layers.len()
    }

    #[test]
    fn a_layer_equal_to_an_earlier_one_is_not_shaded_again() {
        let front = vec![2.0f32; 64];
        let mut back = front.clone();
        assert_eq!(kept(vec![&front, &back, &front]), 1);
        back[5] = 3.0;
        assert_eq!(kept(vec![&front, &back, &front]), 2);
    }
}
