//! Marking a convex polygon of any number of edges (a solid's outline,
//! `solids.rs`): `cover::mark` for a cover too long to test every plane
//! at every cell.
//!
//! Per row of cells, each half-plane a + b x + c y >= 0 holds right of
//! (b > 0) or left of (b < 0) a root x(y) = -(a + c y) / b, which moves
//! between its values at the row's two ends: outside that band the plane
//! holds, or fails, on the whole row. The polygon may hold only where
//! every plane may (the row's span); inside the span, a cell is decided
//! by the planes whose band it meets (the few edges crossing the row,
//! `active`), each tested on the cell's box and, where it straddles, on
//! the cell's samples, as `cover::mark` tests a cover's. Only the edges
//! whose corners' rows meet the row's are taken: a convex polygon's part
//! in a band of rows is bounded by the edges crossing it. A plane with no
//! x term (b = 0) holds on the row, fails, or is active on every cell.
//! The bands are widened by `x_span`'s hair, so a plane is only taken to
//! hold where its box test would find it does.

use super::cells::Cells;
use super::cover::{inside, HalfPlane};

/// Marks in `mask` the samples of the cells `range` inside every plane of
/// `planes`, the edges of a convex polygon whose corners span the rows
/// `ys` (padded; infinite for a plane that is no edge, as the side of an
/// eye-view point: it is taken on every row); `open` is kept as
/// `cover::mark` keeps it. `active` is a buffer.
pub(crate) fn mark_polygon(
    planes: &[HalfPlane],
    ys: &[[f32; 2]],
    cells: &Cells,
    range: ([usize; 2], [usize; 2]),
    mask: &mut [u64],
    open: &mut usize,
    active: &mut Vec<HalfPlane>,
) {
    let ([ix0, ix1], [iy0, iy1]) = range;
    for iy in iy0..=iy1 {
        let [y0, y1] = cells.row_y[iy];
        if !(y0 <= y1) {
            continue;
        }
        // The span where every plane may hold, and the planes whose band
        // falls inside it.
        let (mut xa, mut xb) = (f32::NEG_INFINITY, f32::INFINITY);
        active.clear();
        let mut empty = false;
        let mut crossed = false;
        for (p, &[ya, yb]) in planes.iter().zip(ys) {
            // An edge whose corners' rows miss this one bounds nothing
            // here (the polygon is convex).
            if yb < y0 || ya > y1 {
                continue;
            }
            crossed |= ya.is_finite();
            if p.b == 0.0 {
                match p.on_box([-f32::MAX, y0], [f32::MAX, y1]) {
                    Some(true) => {}
                    Some(false) => empty = true,
                    None => active.push(*p),
                }
                continue;
            }
            let [lo, hi] = band(p, y0, y1);
            if !(lo <= hi) {
                // Not finite: decided cell by cell.
                active.push(*p);
                continue;
            }
            if p.b > 0.0 {
                xa = xa.max(lo);
            } else {
                xb = xb.min(hi);
            }
            active.push(*p);
        }
        if empty || !crossed || !(xa <= xb) {
            continue;
        }
        let (ca, _) = cells.cell_of(xa.max(cells.rect[0][0]), y0);
        let (cb, _) = cells.cell_of(xb.min(cells.rect[0][1]), y0);
        for ix in ix0.max(ca)..=ix1.min(cb) {
            let k = iy * cells.c + ix;
            let full = cells.full[k];
            if mask[k] == full {
                continue;
            }
            let (lo, hi) = (cells.lo[k], cells.hi[k]);
            let mut straddle = 0u64;
            let mut miss = false;
            for (l, p) in active.iter().enumerate() {
                match p.on_box(lo, hi) {
                    Some(false) => {
                        miss = true;
                        break;
                    }
                    Some(true) => {}
                    None if l < 64 => straddle |= 1 << l,
                    // More straddling planes than a word: test them all.
                    None => straddle = u64::MAX,
                }
            }
            if miss {
                continue;
            }
            let bits = if straddle == 0 {
                full
            } else {
                inside(cells, k, active, straddle) & full
            };
            let before = mask[k];
            mask[k] |= bits;
            if before != full && mask[k] == full {
                *open -= 1;
            }
        }
    }
}

/// The x range over which plane `p`'s root moves on the band y in
/// [y0, y1], widened by `cover`'s hair; inverted where not finite.
#[inline(always)]
fn band(p: &HalfPlane, y0: f32, y1: f32) -> [f32; 2] {
    let inv = 1.0 / p.b;
    let (r0, r1) = (-(p.a + y0 * p.c) * inv, -(p.a + y1 * p.c) * inv);
    let (lo, hi) = (r0.min(r1), r0.max(r1));
    let terms = p.a.abs() + (y0 * p.c).abs().max((y1 * p.c).abs());
    let pad = 1e-4 * (1.0 + lo.abs().max(hi.abs())) + 1e-5 * terms * inv.abs();
    let b = [lo - pad, hi + pad];
    if b[0].is_finite() && b[1].is_finite() {
        b
    } else {
        [f32::INFINITY, f32::NEG_INFINITY]
    }
}
