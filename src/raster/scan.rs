//! The scan of one set-up triangle: exact i64 edge functions stepped over the
//! texel centers of its bounding box, with the tie rule that keeps shared
//! edges watertight, and the height of the bands of rows that the map is cut
//! into for parallel rasterization.

use super::edge::owns_ties;
use super::setup::{SetupTri, ONE};
use crate::geom::light::MapGrid;

/// Rows per band: enough bands for load balance, few enough that binning is cheap.
pub(super) fn band_rows(height: usize) -> usize {
    let bands = (rayon::current_num_threads() * 8).max(1);
    height.div_ceil(bands).max(1)
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

#[cfg(test)]
mod tests {
    use super::super::edge::covers;
    use super::*;
    use crate::raster::depth_plane::DepthPlane;

    /// `covers` at a texel center agrees with what `raster_tri` writes
    /// there, over random triangles around one center (the ones `setup`
    /// leaves out when they miss it) and ties on edges.
    #[test]
    fn covers_agrees_with_the_scan() {
        let grid = MapGrid::new(4, 4, [1.0, 1.0]).unwrap();
        let mut seed = 11u64;
        let mut r = |n: i64| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) % n as u64) as i64
        };
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..20000 {
            // Vertices within a texel of center (1, 1), on a coarse subpixel
            // lattice so that centers often lie exactly on an edge.
            let (cx, cy) = (ONE + ONE / 2, ONE + ONE / 2);
            let mut x = [0i64; 3].map(|_| cx + (r(9) - 4) * ONE / 4);
            let mut y = [0i64; 3].map(|_| cy + (r(9) - 4) * ONE / 4);
            let area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
            if area == 0 {
                continue;
            }
            if area < 0 {
                x.swap(1, 2);
                y.swap(1, 2);
            }
            let t = SetupTri {
                x,
                y,
                depth: DepthPlane::new(0.5, 0.0, 0.0),
                i0: 0,
                i1: 3,
                j0: 0,
                j1: 3,
            };
            let mut hit = false;
            raster_tri(&t, &grid, 0..grid.height, |k, _| hit |= k == grid.width + 1);
            assert_eq!(covers(&x, &y, cx, cy), hit, "{x:?} {y:?}");
            if hit {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(inside > 1000 && outside > 1000, "{inside} {outside}");
    }
}
