//! Soft shadow maps as published (Atty et al. 2005, §3): every occluder texel
//! becomes a micro-patch parallel to the light at its depth; its occlusion of
//! the light seen from a receiver point is the overlap of its back-projection
//! onto the light with the light rectangle (§3.4); occlusions are summed and
//! clamped; with two occluder layers (§3.5) the larger occlusion wins.
//!
//! Geometry in light space. A receiver point at tangent (xr, yr), depth zR, and
//! a micro-patch covering tangent [x0, x1] x [y0, y1] at depth zO < zR. The ray
//! from the receiver through the patch point at tangent xq meets the light's
//! plane at X = k (xq - xr) with k = zR zO / (zR - zO) = 1 / (1/zO - 1/zR).
//! In units of the light's width, shifted so the light is [0, 1]:
//!     [a, b] = [(x0 - xr) r / Lx + 1/2, (x1 - xr) r / Lx + 1/2],  r = 1/(wO - wR)
//! with w = 1/z; the same along y; the occlusion is |[a,b] ∩ [0,1]| |[c,d] ∩ [0,1]|
//! (the paper's SAT trick). The patch reaches receivers within
//!     |xq - xr| < L/2 (wO - wR)
//! which is its penumbra extent (§3.3) in tangent units.
//!
//! The CPU kernel is a gather: groups of LANES receivers (an 8x8 tile of the
//! output map, or 64 neighbouring sample points) sum over the occluder texels
//! inside the union of their possible extents. The lanes are receivers, so the
//! inner loop over occluder texels is long and branch-free, and each occluder
//! texel costs a few vector instructions for the whole group. Bands of output
//! rows are split across threads without locks or atomics. Occluder rows and
//! BLOCK-wide runs of them carry their nearest depth, which bounds the extent
//! they can reach. The sum stops at 1: contributions are non-negative and the
//! result is clamped, so stopping there is exact.

use super::{LightPoint, ShadowInputs, ShadowMethod};
use rayon::prelude::*;

/// The published method.
pub struct Ssm;

/// Added to d^2 (d = 1/zO - 1/zR) in the division: keeps 0 / 0 away where
/// occluder and receiver share a depth (there the clipped intervals are empty
/// and the contribution is exactly 0); negligible against any real d^2.
const D2_MIN: f32 = 1e-36;
/// Receivers per group (vector lanes: 4 AVX-512 registers). Fixed in the
/// source, so the summation order (and the result) does not depend on the
/// SIMD width the CPU offers. A power of two.
const LANES: usize = 64;
const _: () = assert!(LANES.is_power_of_two());
/// Map texels are shaded in square tiles of TILE_W x ROWS_PER_GROUP
/// receivers: one visit of an occluder row serves the whole tile, and a
/// square keeps the union of the receivers' extents small. (Measured on the
/// bunny at 256²: 8x8 beats 16x1 by 1.4x and 16x4 or 32x2 by 5-15%.)
const TILE_W: usize = 8;
const ROWS_PER_GROUP: usize = LANES / TILE_W;
/// Occluder texels per block for the block-level depth bound (8 measured
/// best: 16 costs 5% more, 32 15%).
const BLOCK: usize = 8;

type Lanes = [f32; LANES];

/// One occluder depth layer, in the form the kernel reads.
struct Layer {
    /// 1/depth per texel, 0 where empty (so it is never in front of a receiver).
    w: Vec<f32>,
    /// Largest 1/depth of each BLOCK-wide block of each row (`blocks_per_row` a row).
    block_w_max: Vec<f32>,
    rows: Vec<RowSpan>,
    w_max: f32,
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
    fn new(depth: &[f32], width: usize) -> Layer {
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
        Layer {
            w,
            block_w_max,
            rows,
            w_max,
        }
    }
}

/// Up to LANES receivers shaded together. Inactive lanes (no receiver) have
/// wr = +inf, which makes every contribution 0.
struct Group {
    xr: Lanes,
    yr: Lanes,
    wr: Lanes,
    /// Bounds over the active lanes.
    wr_min: f32,
    x_lo: f32,
    x_hi: f32,
    y_lo: f32,
    y_hi: f32,
}

impl Group {
    /// `None` when no lane has a receiver in front of the light.
    fn new(pts: impl Iterator<Item = (f32, f32, f32)>) -> Option<Group> {
        let mut g = Group {
            xr: [0.0; LANES],
            yr: [0.0; LANES],
            wr: [f32::INFINITY; LANES],
            wr_min: f32::INFINITY,
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
            g.x_lo = g.x_lo.min(x);
            g.x_hi = g.x_hi.max(x);
            g.y_lo = g.y_lo.min(y);
            g.y_hi = g.y_hi.max(y);
        }
        g.wr_min.is_finite().then_some(g)
    }
}

/// min and max as x86's minps/maxps read them (the second operand wins on NaN,
/// and no NaN reaches them here): one instruction each, where f32::min's NaN
/// rules cost three.
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
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
    /// The occluder grid from here on.
    width: usize,
    height: usize,
    blocks_per_row: usize,
    tx: f32,
    ty: f32,
    /// Left edge (tangent x) of every occluder column, and the left edge in
    /// half-light units (2 x0 / Lx).
    col_x0: Vec<f32>,
    col_x0_scaled: Vec<f32>,
    /// Center (tangent y) of every row.
    row_y: Vec<f32>,
    /// Tangent half-size of a texel.
    hw: f32,
    hh: f32,
    inv_half_lx: f32,
    inv_half_ly: f32,
    half_lx: f32,
    half_ly: f32,
    layers: Vec<Layer>,
}

impl Kernel {
    fn new(inputs: &ShadowInputs) -> Kernel {
        // Occluder texels live on the occluder grid; receivers on the output grid.
        let g = &inputs.occluder_grid;
        let r = &inputs.grid;
        let (hw, hh) = g.half_texel();
        Kernel {
            rec_width: r.width,
            rec_col_x: (0..r.width).map(|i| r.x_of(i) as f32).collect(),
            rec_row_y: (0..r.height).map(|j| r.y_of(j) as f32).collect(),
            width: g.width,
            height: g.height,
            blocks_per_row: g.width.div_ceil(BLOCK),
            tx: g.tx as f32,
            ty: g.ty as f32,
            col_x0: (0..g.width).map(|i| (g.x_of(i) - hw) as f32).collect(),
            row_y: (0..g.height).map(|j| g.y_of(j) as f32).collect(),
            hw: hw as f32,
            hh: hh as f32,
            col_x0_scaled: (0..g.width)
                .map(|i| ((g.x_of(i) - hw) * 2.0 / inputs.light_size[0]) as f32)
                .collect(),
            inv_half_lx: (2.0 / inputs.light_size[0]) as f32,
            inv_half_ly: (2.0 / inputs.light_size[1]) as f32,
            half_lx: (0.5 * inputs.light_size[0]) as f32,
            half_ly: (0.5 * inputs.light_size[1]) as f32,
            layers: inputs
                .occluder_layers
                .iter()
                .map(|d| Layer::new(d, g.width))
                .collect(),
        }
    }

    /// Continuous row coordinate of tangent y, in units where row j's center is j.
    #[inline(always)]
    fn row_coord(&self, y: f32) -> f32 {
        (1.0 - y / self.ty) * 0.5 * self.height as f32 - 0.5
    }

    #[inline(always)]
    fn col_coord(&self, x: f32) -> f32 {
        (x / self.tx + 1.0) * 0.5 * self.width as f32 - 0.5
    }

    /// Summed occlusion of one layer for each lane, clamped to 1.
    #[inline(always)]
    fn layer_occlusion(&self, layer: &Layer, g: &Group) -> Lanes {
        let mut acc = [0f32; LANES];
        if layer.w_max <= g.wr_min {
            return acc;
        }
        let reach_y = self.hh + self.half_ly * (layer.w_max - g.wr_min);
        let last = self.height as isize - 1;
        let j_lo = (self.row_coord(g.y_hi + reach_y).floor() as isize).clamp(0, last);
        let j_hi = (self.row_coord(g.y_lo - reach_y).ceil() as isize).clamp(0, last);
        // Visit rows outward from the receivers' own rows: in umbra the sums
        // reach 1 soonest that way.
        let j_c = (self.row_coord(0.5 * (g.y_lo + g.y_hi)).round() as isize).clamp(j_lo, j_hi);
        let (mut up, mut down) = (j_c, j_c + 1);
        while up >= j_lo || down <= j_hi {
            let mut touched = false;
            for j in [up, down] {
                if j >= j_lo && j <= j_hi {
                    touched |= self.add_row(&mut acc, layer, j as usize, g);
                }
            }
            // acc holds 4x the occlusion (see add_row).
            if touched && acc.iter().all(|&a| a >= 4.0) {
                return [1.0; LANES];
            }
            up -= 1;
            down += 1;
        }
        acc.map(|a| (0.25 * a).min(1.0))
    }

    /// Adds occluder row j's micro-patches to every lane; false when the row
    /// cannot reach any lane.
    #[inline(always)]
    fn add_row(&self, acc: &mut Lanes, layer: &Layer, j: usize, g: &Group) -> bool {
        let span = layer.rows[j];
        if span.first >= span.last || span.w_max <= g.wr_min {
            return false;
        }
        let dw = span.w_max - g.wr_min;
        let yc = self.row_y[j];
        let dy = (g.y_lo - yc).max(yc - g.y_hi).max(0.0);
        if dy >= self.hh + self.half_ly * dw {
            return false;
        }
        let reach_x = self.hw + self.half_lx * dw;
        let i_lo = (self.col_coord(g.x_lo - reach_x).floor() as isize).max(span.first as isize);
        let i_hi = (self.col_coord(g.x_hi + reach_x).ceil() as isize + 1).min(span.last as isize);
        if i_lo >= i_hi {
            return false;
        }
        // In half-light units (2x / Lx, 2y / Ly), relative to each lane's
        // receiver. The micro-patch [x0, x1] seen from the receiver covers, on
        // the light, r [x0 - xr, x1 - xr] with r = 1/d, d = wO - wR, which is
        // intersected with the light [-1, 1]; equivalently [x0 - xr, x1 - xr]
        // is clipped to [-d, d] and the length scaled by r. The area fraction is
        // then cx cy / (4 d^2): one division per pair, and no mask, since for
        // d <= 0 the clipped intervals are empty. The 1/4 is applied at the end.
        let mut xr = [0f32; LANES];
        let mut nay0 = [0f32; LANES];
        let mut ay1 = [0f32; LANES];
        for l in 0..LANES {
            xr[l] = g.xr[l] * self.inv_half_lx;
            nay0[l] = (g.yr[l] - (yc - self.hh)) * self.inv_half_ly;
            ay1[l] = (yc + self.hh - g.yr[l]) * self.inv_half_ly;
        }
        let wx = 2.0 * self.hw * self.inv_half_lx;
        let row = &layer.w[j * self.width..(j + 1) * self.width];
        let blocks = &layer.block_w_max[j * self.blocks_per_row..(j + 1) * self.blocks_per_row];
        let (i_lo, i_hi) = (i_lo as usize, i_hi as usize);
        // Trim the run to the first and last block whose nearest texel can
        // reach a lane; blocks in between are shaded whole (one long loop,
        // one branch per texel, rather than a loop per block).
        let reaches = |b: usize| {
            let bdw = blocks[b] - g.wr_min;
            let s = (b * BLOCK).max(i_lo);
            let e = ((b + 1) * BLOCK).min(i_hi);
            let gap = (g.x_lo - (self.col_x0[e - 1] + 2.0 * self.hw)).max(self.col_x0[s] - g.x_hi);
            bdw > 0.0 && gap < self.half_lx * bdw && dy < self.hh + self.half_ly * bdw
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
        for (&w, &x0) in row[s..e].iter().zip(&self.col_x0_scaled[s..e]) {
            let x1 = x0 + wx;
            if w <= g.wr_min {
                continue; // empty, or behind every lane's receiver
            }
            for l in 0..LANES {
                let d = w - g.wr[l];
                // |[a, b] ∩ [-d, d]| = min(b, d) + min(-a, d) when >= 0.
                let cx = min(x1 - xr[l], d) + min(xr[l] - x0, d);
                let cy = min(ay1[l], d) + min(nay0[l], d);
                // d^2 + D2_MIN keeps 0/0 away where d = 0 (then cx, cy <= 0).
                acc[l] += max(cx, 0.0) * max(cy, 0.0) / d.mul_add(d, D2_MIN);
            }
        }
        true
    }

    /// Visibility per lane: 1 - the largest layer occlusion.
    #[inline(always)]
    fn shade_group(&self, g: &Group) -> Lanes {
        let mut occ = [0f32; LANES];
        // Back layer first: it is the cheaper one (farther, so its micro-patches
        // reach less far) and, on solid occluders, the one whose sum reaches 1
        // in umbra (the front layer leaves gaps between micro-patches on curved
        // surfaces, §4.1.2), which makes the other layer unnecessary. The max
        // does not depend on the order. (Measured 5% faster on the bunny.)
        for layer in self.layers.iter().rev() {
            let o = self.layer_occlusion(layer, g);
            for l in 0..LANES {
                occ[l] = occ[l].max(o[l]);
            }
            if occ.iter().all(|&o| o >= 1.0) {
                break;
            }
        }
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
    fn shade_row_generic(&self, j0: usize, receiver: &[f32], out: &mut [f32]) {
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
            if let Some(g) = Group::new(pts) {
                let v = self.shade_group(&g);
                for r in 0..rows {
                    out[r * w + c..r * w + e].copy_from_slice(&v[r * TILE_W..r * TILE_W + (e - c)]);
                }
            }
        }
    }

    #[inline(always)]
    fn shade_points_generic(&self, pts: &[LightPoint], out: &mut [f32]) {
        for (o, p) in out.chunks_mut(LANES).zip(pts.chunks(LANES)) {
            if let Some(g) = Group::new(p.iter().map(|p| (p.x, p.y, p.z))) {
                let v = self.shade_group(&g);
                o.copy_from_slice(&v[..o.len()]);
            }
        }
    }
}

// Runtime dispatch: the same source compiled for AVX-512, AVX2+FMA or the
// baseline. The lanes are fixed in the source, so all three give the same bits.
impl Kernel {
    fn shade_row(&self, j: usize, receiver: &[f32], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_row_avx512(j, receiver, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_row_avx2(j, receiver, out) };
            }
        }
        self.shade_row_generic(j, receiver, out)
    }

    fn shade_points(&self, pts: &[LightPoint], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_points_avx512(pts, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_points_avx2(pts, out) };
            }
        }
        self.shade_points_generic(pts, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_row_avx512(&self, j: usize, receiver: &[f32], out: &mut [f32]) {
        self.shade_row_generic(j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_row_avx2(&self, j: usize, receiver: &[f32], out: &mut [f32]) {
        self.shade_row_generic(j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_points_avx512(&self, pts: &[LightPoint], out: &mut [f32]) {
        self.shade_points_generic(pts, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_points_avx2(&self, pts: &[LightPoint], out: &mut [f32]) {
        self.shade_points_generic(pts, out)
    }
}

impl ShadowMethod for Ssm {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        let k = Kernel::new(inputs);
        let w = k.rec_width;
        let mut out = vec![1f32; inputs.grid.len()];
        out.par_chunks_mut(w * ROWS_PER_GROUP)
            .zip(inputs.receiver.par_chunks(w * ROWS_PER_GROUP))
            .enumerate()
            .for_each(|(t, (o, r))| k.shade_row(t * ROWS_PER_GROUP, r, o));
        out
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let k = Kernel::new(inputs);
        // Shade neighbours together: sort the points by the texel they fall in,
        // so that each group's union of extents stays small.
        let key = |p: &LightPoint| {
            let j = k.row_coord(p.y).round().clamp(0.0, k.height as f32 - 1.0) as u64;
            let i = k.col_coord(p.x).round().clamp(0.0, k.width as f32 - 1.0) as u64;
            // Tile-major order, so that runs of LANES points form compact tiles.
            let (t, r) = (TILE_W as u64, ROWS_PER_GROUP as u64);
            let tiles_x = (k.width as u64).div_ceil(t);
            (((j / r) * tiles_x + i / t) * r + j % r) * t + i % t
        };
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        order.par_sort_by_key(|&n| key(&points[n as usize]));
        let sorted: Vec<LightPoint> = order.iter().map(|&n| points[n as usize]).collect();
        let mut shaded = vec![1f32; points.len()];
        shaded
            .par_chunks_mut(LANES * 4)
            .zip(sorted.par_chunks(LANES * 4))
            .for_each(|(o, p)| k.shade_points(p, o));
        let mut out = vec![1f32; points.len()];
        for (&n, &v) in order.iter().zip(&shaded) {
            out[n as usize] = v;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::MapGrid;

    /// The published method written as plainly as possible, in f64: every
    /// occluder texel against every receiver texel, no bounds, no early exit.
    fn brute_force(inputs: &ShadowInputs) -> Vec<f32> {
        let g = &inputs.grid;
        let og = &inputs.occluder_grid;
        let (hw, hh) = og.half_texel();
        let [lx, ly] = inputs.light_size;
        let overlap = |a: f64, b: f64| (b.clamp(0.0, 1.0) - a.clamp(0.0, 1.0)).max(0.0);
        let mut out = vec![1f32; g.len()];
        for jr in 0..g.height {
            for ir in 0..g.width {
                let zr = inputs.receiver[jr * g.width + ir] as f64;
                if !zr.is_finite() {
                    continue;
                }
                let (xr, yr) = (g.x_of(ir), g.y_of(jr));
                let mut occ = 0f64;
                for layer in &inputs.occluder_layers {
                    let mut sum = 0f64;
                    for jo in 0..og.height {
                        for io in 0..og.width {
                            let zo = layer[jo * og.width + io] as f64;
                            if !(zo < zr) {
                                continue;
                            }
                            let k = zr * zo / (zr - zo);
                            let (xc, yc) = (og.x_of(io), og.y_of(jo));
                            let ox = overlap(
                                k * (xc - hw - xr) / lx + 0.5,
                                k * (xc + hw - xr) / lx + 0.5,
                            );
                            let oy = overlap(
                                k * (yc - hh - yr) / ly + 0.5,
                                k * (yc + hh - yr) / ly + 0.5,
                            );
                            sum += ox * oy;
                        }
                    }
                    occ = occ.max(sum.min(1.0));
                }
                out[jr * g.width + ir] = (1.0 - occ) as f32;
            }
        }
        out
    }

    /// A small deterministic generator (no dev-dependency needed).
    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn kernel_matches_the_brute_force_sum() {
        let mut seed = 7u64;
        for (w, h) in [(37, 29), (16, 16), (1, 9), (50, 1)] {
            let grid = MapGrid::new(w, h, [0.4, 0.3]).unwrap();
            let front: Vec<f32> = (0..w * h)
                .map(|_| {
                    if lcg(&mut seed) < 0.4 {
                        (2.0 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            let back: Vec<f32> = front
                .iter()
                .map(|z| if z.is_finite() { z + 0.5 } else { *z })
                .collect();
            let receiver: Vec<f32> = (0..w * h)
                .map(|_| {
                    if lcg(&mut seed) < 0.9 {
                        (3.2 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            for layers in [vec![&front[..]], vec![&front[..], &back[..]]] {
                let inputs = ShadowInputs {
                    grid,
                    occluder_grid: grid,
                    light_size: [1.0, 0.7],
                    receiver: &receiver,
                    occluder_layers: layers,
                    occluder_triangles: None,
                };
                let fast = Ssm.visibility_map(&inputs);
                let slow = brute_force(&inputs);
                let max = fast
                    .iter()
                    .zip(&slow)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0f32, f32::max);
                assert!(max < 2e-5, "{w}x{h}: max |fast - brute| = {max}");
                assert!(fast.iter().all(|v| (0.0..=1.0).contains(v)));
                // Points at the texel centers give the map's values.
                let pts: Vec<LightPoint> = (0..w * h)
                    .map(|k| LightPoint {
                        x: grid.x_of(k % w) as f32,
                        y: grid.y_of(k / w) as f32,
                        z: receiver[k],
                    })
                    .collect();
                let at_points = Ssm.visibility_points(&inputs, &pts);
                let max = at_points
                    .iter()
                    .zip(&fast)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0f32, f32::max);
                // Same sums, grouped differently: only the summation order differs.
                assert!(max < 1e-5, "points vs map: {max}");
            }
        }
    }

    #[test]
    fn coarser_or_finer_occluder_grids_match_the_brute_force_sum() {
        let mut seed = 11u64;
        let grid = MapGrid::new(40, 24, [0.4, 0.3]).unwrap();
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (3.2 + lcg(&mut seed)) as f32)
            .collect();
        for (ow, oh) in [(13, 9), (64, 50), (1, 1)] {
            let og = MapGrid::new(ow, oh, [0.4, 0.3]).unwrap();
            let front: Vec<f32> = (0..og.len())
                .map(|_| {
                    if lcg(&mut seed) < 0.5 {
                        (2.0 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            let inputs = ShadowInputs {
                grid,
                occluder_grid: og,
                light_size: [0.8, 1.1],
                receiver: &receiver,
                occluder_layers: vec![&front],
                occluder_triangles: None,
            };
            let fast = Ssm.visibility_map(&inputs);
            let slow = brute_force(&inputs);
            let max = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).abs())
                .fold(0f32, f32::max);
            assert!(max < 2e-5, "{ow}x{oh}: {max}");
        }
    }

    #[test]
    fn plate_over_parallel_floor_matches_the_closed_form() {
        // Plate covering tangent [-a, a]^2 at depth zo, floor at depth zr: the
        // occlusion is the overlap of the back-projected square with the light.
        // The map samples the plate on texels: where the plate's edges fall on
        // texel edges the discretized plate is exact, and so is the SSM.
        let n = 64;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (zo, zr, a) = (2.0f64, 4.0f64, 0.25f64);
        let front: Vec<f32> = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < a && y.abs() < a {
                    zo as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver = vec![zr as f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let v = Ssm.visibility_map(&inputs);
        let k = zr * zo / (zr - zo);
        let ov = |c: f64| {
            ((k * (a - c) + 0.5).clamp(0.0, 1.0) - (k * (-a - c) + 0.5).clamp(0.0, 1.0)).max(0.0)
        };
        let mut max = 0f64;
        for j in 0..n {
            for i in 0..n {
                let exact = 1.0 - ov(grid.x_of(i)) * ov(grid.y_of(j));
                max = max.max((v[j * n + i] as f64 - exact).abs());
            }
        }
        // Additive micro-patches of one flat plate tile the back-projection
        // exactly, so only f32 rounding remains.
        assert!(max < 1e-5, "max error {max}");
    }
}

#[cfg(test)]
mod bench {
    use super::*;
    use crate::light::MapGrid;

    /// Times the kernel on maps dumped to /tmp (a development aid, ignored by
    /// default): cargo test --release bench_dumped -- --ignored --nocapture
    #[test]
    #[ignore]
    fn bench_dumped() {
        let read = |p: &str| -> Vec<f32> {
            std::fs::read(p)
                .unwrap()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect()
        };
        let (front, back, rec) = (
            read("/tmp/front.f32"),
            read("/tmp/back.f32"),
            read("/tmp/rec.f32"),
        );
        let grid = MapGrid::new(256, 256, [0.3137646436112252, 0.3050549377029778]).unwrap();
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &rec,
            occluder_layers: vec![&front, &back],
            occluder_triangles: None,
        };
        let mut ts = vec![];
        let mut sum = 0.0;
        for _ in 0..30 {
            let t = std::time::Instant::now();
            let v = Ssm.visibility_map(&inputs);
            ts.push(t.elapsed().as_secs_f64());
            sum += v.iter().map(|&x| x as f64).sum::<f64>();
        }
        ts.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!("median {:.2} ms (checksum {sum:.3})", ts[15] * 1e3);
    }
}
