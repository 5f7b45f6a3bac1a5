//! Connected micro-quads: the corner depths that close the gaps between
//! neighbouring micro-patches (the gaps of Atty et al. 2005, §4.1.2).
//!
//! A micro-patch is flat at its texel's depth. Between two neighbours at
//! different depths light passes through: each back-projects its shared edge
//! at its own depth, so the two back-projections leave a gap on the light
//! (or overlap). The literature that followed the paper connects neighbouring
//! depth samples into one surface (micro-quads, Schwarz & Stamminger 2008;
//! gap filling, Guennebaud et al. 2006). Here every texel becomes a quad whose
//! four corners carry their own 1/depth, chosen so that two connected
//! neighbours give their shared edge the same two corner depths: the edge
//! then back-projects to the same segment from both sides and no light
//! passes between them.
//!
//! The rule, per texel corner (the centre of the 2x2 block of texels around
//! it): the texels of the block connected to this one through the block's
//! four edges form its component, and
//!   * all four: the corner is their mean 1/depth (exact on a plane);
//!   * three (the fourth is across a discontinuity): the mean of the two
//!     diagonal to each other in the component, whose midpoint the corner is;
//!   * two along an edge: their mean, moved half a texel across the edge by
//!     their mean slope there;
//!   * one: the texel's depth moved by its own slope half a texel along x and
//!     along y (a plane's corner; a silhouette texel's outer edge).
//!
//! Every texel of a component gets the same value, summed in the same order,
//! so connected neighbours share their corners bit for bit. A texel's slope
//! toward a side is the difference to its neighbour there when connected,
//! else the difference from the opposite neighbour (extrapolated), else 0.
//!
//! The discontinuity rule: neighbours are connected where the surface between
//! them would be at most `MAX_SLOPE` steep against the light's view
//! direction, |z_a - z_b| <= MAX_SLOPE * (texel width in tangent units) *
//! min(z_a, z_b). Two objects at different depths that meet in the map are a
//! step far steeper than that and stay apart; surfaces tilted up to
//! atan(MAX_SLOPE) from the light's direction connect. The kernel back-projects
//! a quad as the bounding rectangle of its projected corners (its projection
//! lies inside it: a segment projects to a segment), which keeps the
//! rank-table lookups of an axis-aligned rectangle.

use rayon::prelude::*;

/// Steepest connected surface: tan of the angle from the light's direction
/// (4: 76°). Measured with 256 samples at 256² against 4096-sample `exact`
/// on the study's four scenes and tilted plates: from 1 to 16 the error moves
/// by at most 0.001 (no threshold in that range bridges a real gap in those
/// scenes); 4 with the extrapolated border corners was best or within 0.0003
/// of the best on each.
pub const MAX_SLOPE: f32 = 4.0;

/// 1/depth per texel, 0 where empty (no finite positive depth): the form
/// the kernels read a depth layer in (`Layer::from_depth`) and `corners`
/// takes (the GPU twin computes its corners from it too).
pub fn inverse_depth(depth: &[f32]) -> Vec<f32> {
    depth
        .par_iter()
        .map(|&z| {
            if z.is_finite() && z > 0.0 {
                1.0 / z
            } else {
                0.0
            }
        })
        .collect()
}

/// Corner 1/depths per texel: [top-left, top-right, bottom-left,
/// bottom-right], top meaning the row above (smaller j, larger y). 0 for
/// empty texels. `w`: 1/depth per texel (0: empty), `width` x `height`;
/// `dx`, `dy`: a texel's tangent width and height.
pub fn corners(w: &[f32], width: usize, height: usize, dx: f32, dy: f32) -> Vec<[f32; 4]> {
    let at = |i: isize, j: isize| -> f32 {
        if i < 0 || j < 0 || i >= width as isize || j >= height as isize {
            0.0
        } else {
            w[j as usize * width + i as usize]
        }
    };
    // Connected: both occupied, and |z_a - z_b| <= s t min(z_a, z_b) for
    // z = 1/w, which is |a - b| / (a b) <= s t / max(a, b), that is
    // |a - b| <= s t min(a, b).
    let linked = |a: f32, b: f32, t: f32| -> bool {
        a > 0.0 && b > 0.0 && (a - b).abs() <= MAX_SLOPE * t * a.min(b)
    };
    // Slope of texel (i, j) toward +x (sx = 1) or -x (sx = -1), per texel.
    let slope_x = |i: isize, j: isize, sx: isize| -> f32 {
        let c = at(i, j);
        let (n, o) = (at(i + sx, j), at(i - sx, j));
        if linked(c, n, dx) {
            n - c
        } else if linked(c, o, dx) {
            c - o
        } else {
            0.0
        }
    };
    let slope_y = |i: isize, j: isize, sy: isize| -> f32 {
        let c = at(i, j);
        let (n, o) = (at(i, j + sy), at(i, j - sy));
        if linked(c, n, dy) {
            n - c
        } else if linked(c, o, dy) {
            c - o
        } else {
            0.0
        }
    };
    let mut out = vec![[0f32; 4]; w.len()];
    out.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
        let j = j as isize;
        for (i, o) in row.iter_mut().enumerate() {
            let i = i as isize;
            if at(i, j) <= 0.0 {
                continue;
            }
            // Corners in slot order: (sx, sy) with sy = -1 the row above.
            for (slot, (sx, sy)) in [(-1, -1), (1, -1), (-1, 1), (1, 1)].into_iter().enumerate() {
                o[slot] = corner(&at, &linked, &slope_x, &slope_y, i, j, sx, sy, dx, dy);
            }
        }
    });
    out
}

/// The corner of texel (i, j) toward (sx, sy), computed from the 2x2 block
/// around the corner in an order that does not depend on which of the
/// block's texels asks (so connected texels share the bits).
#[allow(clippy::too_many_arguments)]
fn corner(
    at: &impl Fn(isize, isize) -> f32,
    linked: &impl Fn(f32, f32, f32) -> bool,
    slope_x: &impl Fn(isize, isize, isize) -> f32,
    slope_y: &impl Fn(isize, isize, isize) -> f32,
    i: isize,
    j: isize,
    sx: isize,
    sy: isize,
    dx: f32,
    dy: f32,
) -> f32 {
    // The block's texels: q[b] at (i0 + (b & 1), j0 + (b >> 1)), b = 0
    // top-left, 1 top-right, 2 bottom-left, 3 bottom-right.
    let i0 = if sx < 0 { i - 1 } else { i };
    let j0 = if sy < 0 { j - 1 } else { j };
    let pos = |b: usize| (i0 + (b & 1) as isize, j0 + (b >> 1) as isize);
    let q: [f32; 4] = std::array::from_fn(|b| {
        let (x, y) = pos(b);
        at(x, y)
    });
    // The block's edges: 0-1 and 2-3 along x, 0-2 and 1-3 along y.
    let e01 = linked(q[0], q[1], dx);
    let e23 = linked(q[2], q[3], dx);
    let e02 = linked(q[0], q[2], dy);
    let e13 = linked(q[1], q[3], dy);
    let edges = [(0, 1, e01), (2, 3, e23), (0, 2, e02), (1, 3, e13)];
    // The asking texel's component in the block (a bit set), by flooding.
    let me = ((j - j0) * 2 + (i - i0)) as usize;
    let mut comp = 1u8 << me;
    for _ in 0..3 {
        for &(a, b, on) in &edges {
            if on && (comp >> a & 1 == 1 || comp >> b & 1 == 1) {
                comp |= 1 << a | 1 << b;
            }
        }
    }
    match comp.count_ones() {
        4 => ((q[0] + q[1]) + (q[2] + q[3])) * 0.25,
        3 => {
            // The missing texel's diagonal partner and the two others: the
            // corner is the midpoint of the two diagonal to each other.
            let missing = (0..4).find(|b| comp >> b & 1 == 0).unwrap_or(0);
            let (a, b) = match missing {
                0 | 3 => (1, 2),
                _ => (0, 3),
            };
            (q[a] + q[b]) * 0.5
        }
        2 => {
            let (a, b) = match comp {
                0b0011 => (0, 1),
                0b1100 => (2, 3),
                0b0101 => (0, 2),
                _ => (1, 3),
            };
            let ((ia, ja), (ib, jb)) = (pos(a), pos(b));
            if ja == jb {
                // Along x: move across in y, toward the corner's row side.
                let s = if ja == j0 { 1 } else { -1 };
                (q[a] + q[b]) * 0.5 + (slope_y(ia, ja, s) + slope_y(ib, jb, s)) * 0.25
            } else {
                let s = if ia == i0 { 1 } else { -1 };
                (q[a] + q[b]) * 0.5 + (slope_x(ia, ja, s) + slope_x(ib, jb, s)) * 0.25
            }
        }
        _ => {
            let c = q[me];
            c + (slope_x(i, j, sx) + slope_y(i, j, sy)) * 0.5
        }
    }
}

/// `corner_inv` (`bitmask.rs`) for the four corners, the same values, as
/// one 4-wide division: written per corner, the compiler computed both
/// candidates' reciprocals with 8 scalar divisions, which profiled at a
/// fifth of the whole-tile kernel. Computed per (quad, tile), or once per
/// quad for the receivers' common plane (`Layer::plane_invs`).
#[inline(always)]
pub(in crate::methods) fn corner_invs(c: &[f32; 4], wr: f32, d: f32) -> [f32; 4] {
    let mut den = [1f32; 4];
    for k in 0..4 {
        let dc = c[k] - wr;
        den[k] = if dc > 0.0 { dc } else { d };
    }
    let mut inv = [0f32; 4];
    for k in 0..4 {
        inv[k] = 1.0 / den[k];
    }
    if d > 0.0 {
        inv
    } else {
        [0.0; 4]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(width: usize, height: usize, a: f32, b: f32, c: f32) -> Vec<f32> {
        (0..width * height)
            .map(|k| a + b * (k % width) as f32 + c * (k / width) as f32)
            .collect()
    }

    #[test]
    fn a_plane_gets_its_own_corners_everywhere_even_at_the_border() {
        // 1/depth linear in the texel indices: every corner is the plane's
        // value there, the border's extrapolated.
        let (wd, ht) = (7, 5);
        let w = plane(wd, ht, 0.5, 0.001, -0.0007);
        let c = corners(&w, wd, ht, 0.01, 0.01);
        for (k, ck) in c.iter().enumerate() {
            let (i, j) = ((k % wd) as f32, (k / wd) as f32);
            let want = |di: f32, dj: f32| 0.5 + 0.001 * (i + di) - 0.0007 * (j + dj);
            let expect = [
                want(-0.5, -0.5),
                want(0.5, -0.5),
                want(-0.5, 0.5),
                want(0.5, 0.5),
            ];
            for s in 0..4 {
                assert!((ck[s] - expect[s]).abs() < 1e-6, "{k} {s}: {ck:?}");
            }
        }
    }

    #[test]
    fn connected_neighbours_share_corner_bits_and_a_step_splits_them() {
        // Two plates side by side in the map, a depth step between columns
        // 3 and 4 far steeper than MAX_SLOPE; a gentle bump inside each.
        let (wd, ht) = (8, 6);
        let mut w = vec![0f32; wd * ht];
        for j in 0..ht {
            for i in 0..wd {
                let base = if i < 4 { 0.5 } else { 0.3 };
                w[j * wd + i] = base + 0.0004 * ((i * 7 + j * 3) % 5) as f32;
            }
        }
        let c = corners(&w, wd, ht, 0.01, 0.01);
        let k = |i: usize, j: usize| j * wd + i;
        for j in 0..ht {
            for i in 0..wd - 1 {
                let (l, r) = (c[k(i, j)], c[k(i + 1, j)]);
                if i == 3 {
                    // The step: the left plate's right edge stays near its depth.
                    assert!(l[1] > 0.45 && r[0] < 0.35, "{l:?} {r:?}");
                } else {
                    assert_eq!(l[1].to_bits(), r[0].to_bits());
                    assert_eq!(l[3].to_bits(), r[2].to_bits());
                }
            }
        }
        for j in 0..ht - 1 {
            for i in 0..wd {
                let (t, b) = (c[k(i, j)], c[k(i, j + 1)]);
                assert_eq!(t[2].to_bits(), b[0].to_bits());
                assert_eq!(t[3].to_bits(), b[1].to_bits());
            }
        }
    }

    #[test]
    fn a_flat_plate_keeps_its_depth_at_every_corner() {
        let w = vec![0.25f32; 12];
        for c in corners(&w, 4, 3, 0.01, 0.02) {
            assert_eq!(c, [0.25; 4]);
        }
    }
}
