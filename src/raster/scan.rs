//! The scan of one set-up triangle: exact i64 edge functions stepped over the
//! texel centers of its bounding box, with the tie rule that keeps shared
//! edges watertight, and the height of the bands of rows that the map is cut
//! into for parallel rasterization.

use super::setup::{SetupTri, ONE};
use crate::geom::light::MapGrid;

/// Rows per band: enough bands for load balance, few enough that binning is cheap.
pub(super) fn band_rows(height: usize) -> usize {
    let bands = (rayon::current_num_threads() * 8).max(1);
    height.div_ceil(bands).max(1)
}

/// Tie rule for a texel center exactly on an edge (dx, dy): of an edge and its
/// reverse exactly one owns the center, so shared edges are neither cracked
/// nor hit twice.
#[inline]
fn owns_ties(dx: i64, dy: i64) -> bool {
    dy < 0 || (dy == 0 && dx > 0)
}

/// Visits the texel centers covered by triangle `t` within `rows`, calling
/// `write(index within the band, depth)` for each.
#[inline(always)]
pub(super) fn raster_tri(
    t: &SetupTri,
    grid: &MapGrid,
    rows: std::ops::Range<usize>,
    mut write: impl FnMut(usize, f32),
) {
    let j_lo = (t.j0 as usize).max(rows.start);
    let j_hi = (t.j1 as usize + 1).min(rows.end);
    if j_lo >= j_hi {
        return;
    }
    let w = grid.width;
    // Edge k goes from vertex k+1 to vertex k+2; its function weighs vertex k.
    let mut a = [0i64; 3]; // dE/dx per texel
    let mut b = [0i64; 3]; // dE/dy per texel
    let mut c = [0i64; 3]; // E at texel center (i0, j_lo)
    let mut bias = [0i64; 3];
    let cx0 = t.i0 as i64 * ONE + ONE / 2;
    let cy0 = j_lo as i64 * ONE + ONE / 2;
    for k in 0..3 {
        let (s, e) = ((k + 1) % 3, (k + 2) % 3);
        let dx = t.x[e] - t.x[s];
        let dy = t.y[e] - t.y[s];
        a[k] = -dy * ONE;
        b[k] = dx * ONE;
        c[k] = dx * (cy0 - t.y[s]) - dy * (cx0 - t.x[s]);
        bias[k] = owns_ties(dx, dy) as i64;
    }
    for j in j_lo..j_hi {
        let dj = (j - j_lo) as i64;
        let mut e = [c[0] + b[0] * dj, c[1] + b[1] * dj, c[2] + b[2] * dj];
        let row = (j - rows.start) * w;
        for i in t.i0 as usize..=t.i1 as usize {
            if e[0] + bias[0] > 0 && e[1] + bias[1] > 0 && e[2] + bias[2] > 0 {
                if let Some(z) = t.depth.depth(i as u32 - t.i0, j as u32 - t.j0) {
                    write(row + i, z);
                }
            }
            e[0] += a[0];
            e[1] += a[1];
            e[2] += a[2];
        }
    }
}
