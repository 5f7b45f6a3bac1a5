//! Percentage-closer filtering over a disk: PCSS's blocker search and
//! filter under a disk light (`pcss.rs`).
//!
//! Under a rectangle PCSS filters over a box (`pcf.rs`) because the
//! occluder points at one depth z that hide part of the light from a
//! receiver R are the light's rectangle mapped by l -> t_r + l (1/z -
//! 1/z_r) (pcss.rs's module doc): a box. That map is a scaling, so under a
//! disk of radius ρ they are the disk t_r ± ρ (1/z - 1/z_r), in the map's
//! pixels an ellipse with semi-axes (hx, hy) (the texels need not be
//! square), and the hidden fraction of the light is the covered fraction
//! of that ellipse. So the filter over the piecewise-constant map is
//!
//! ```text
//!     F(px, py) = Σ_k w_k test(k),   w_k = |E ∩ texel k| / |E|,
//!     E = {(x, y) : ((x - px)/hx)² + ((y - py)/hy)² <= 1},
//! ```
//!
//! and in the coordinates u = (x - px)/hx, v = (y - py)/hy, where E is the
//! unit disk, w_k is the overlap of the texel's rectangle with the unit
//! disk over π (`disk::rect_overlap`, exact). For a planar occluder
//! parallel to the light over a parallel receiver this is again exact:
//! the plate test under a disk.
//!
//! The cells are the box filter's (`pcf::Axis::cells`, the ellipse's
//! bounding box p ± h): every texel in exact mode, or at most `max_taps`
//! strata per axis read bilinearly at their centres, so a disk costs no
//! more reads than its box. Each cell is weighted by its own overlap with
//! the ellipse (a stratum across the rim by its part inside). Half-widths
//! below 1/2 texel are raised to 1/2 as for the box: the smallest filter
//! is the disk of radius half a texel. Outside the map is lit: the part of
//! the ellipse outside it, 1 - |E ∩ map| / |E|, computed from the map's
//! ends (exactly 0 when the ellipse's box is inside), counts as 1.

use super::pcf::Axis;
use crate::geom::light_shape::disk::rect_overlap;
use std::f64::consts::FRAC_1_PI;

/// Calls `f(k, w)` for every texel k = j W + i the ellipse of the axes'
/// centres and half-widths reads, w its share (module doc); the shares sum
/// to the ellipse's fraction inside the map (less what a stratum reads off
/// the map). No call for cells wholly outside the ellipse.
#[inline]
pub(crate) fn visit(ax: &Axis, ay: &Axis, width: usize, mut f: impl FnMut(usize, f64)) {
    let (px, hx) = ax.centre_half();
    let (py, hy) = ay.centre_half();
    ay.cells(|y0, y1, ry| {
        let v = [(y0 - py) / hy, (y1 - py) / hy];
        if v[0] >= 1.0 || v[1] <= -1.0 {
            return;
        }
        ax.cells(|x0, x1, rx| {
            let w = rect_overlap(1.0, [(x0 - px) / hx, (x1 - px) / hx], v) * FRAC_1_PI;
            if !(w > 0.0) {
                return;
            }
            for &(j, fy) in ry {
                for &(i, fx) in rx {
                    f(j * width + i, w * fy * fx);
                }
            }
        });
    });
}

/// The fraction of the ellipse outside the map: 0 when its bounding box
/// is inside, 1 when the box is wholly off the map (or its centre is not
/// finite), else 1 - |E ∩ map| / |E|.
pub(crate) fn outside(ax: &Axis, ay: &Axis) -> f64 {
    let (ox, oy) = (ax.outside(), ay.outside());
    if ox == 0.0 && oy == 0.0 {
        return 0.0;
    }
    if ox >= 1.0 || oy >= 1.0 {
        return 1.0;
    }
    let (px, hx) = ax.centre_half();
    let (py, hy) = ay.centre_half();
    let (w, h) = (ax.texels() as f64, ay.texels() as f64);
    let inside =
        rect_overlap(1.0, [-px / hx, (w - px) / hx], [-py / hy, (h - py) / hy]) * FRAC_1_PI;
    (1.0 - inside).clamp(0.0, 1.0)
}

/// The disk filter of `test` (1 lit, 0 shadowed) over the ellipse of the
/// axes, outside the map lit: Σ w test + outside over Σ w + outside (the
/// box filter's normalisation, so all-lit gives exactly 1).
pub(crate) fn filter(ax: &Axis, ay: &Axis, width: usize, test: impl Fn(usize) -> f32) -> f32 {
    let (mut num, mut den) = (0f64, 0f64);
    visit(ax, ay, width, |k, w| {
        num += w * test(k) as f64;
        den += w;
    });
    let out = outside(ax, ay);
    num += out;
    den += out;
    if den > 0.0 {
        (num / den) as f32
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(px: f64, py: f64, h: [f64; 2], n: [usize; 2], taps: u32) -> (Axis, Axis) {
        (
            Axis::new(px, h[0], n[0], taps, false),
            Axis::new(py, h[1], n[1], taps, false),
        )
    }

    /// Inside the map the shares sum to 1 (exact cells and strata alike),
    /// and all-lit and all-shadowed maps give exactly 1 and about 0.
    #[test]
    fn shares_sum_to_one_inside_the_map() {
        for (h, taps) in [
            ([0.3, 0.3], 16),
            ([3.7, 2.2], 16),
            ([40.0, 25.0], 16),
            ([40.0, 25.0], 256),
        ] {
            let (ax, ay) = axes(64.3, 50.8, h, [128, 100], taps);
            let mut total = 0.0;
            visit(&ax, &ay, 128, |_, w| total += w);
            assert!((total - 1.0).abs() < 1e-12, "{h:?} {taps}: {total}");
            assert_eq!(outside(&ax, &ay), 0.0);
            assert_eq!(filter(&ax, &ay, 128, |_| 1.0), 1.0);
            assert!(filter(&ax, &ay, 128, |_| 0.0) < 1e-12);
        }
    }

    /// A straight edge through the centre hides half the disk; an edge at
    /// u = c hides the circular segment beyond it, (acos c - c √(1 - c²)) / π
    /// of the disk, in exact mode to rounding (edge on texel boundaries).
    #[test]
    fn an_edge_hides_the_disks_segment() {
        let (px, py, h) = (50.0, 40.0, 8.0);
        for edge in [50usize, 53, 56, 44] {
            let (ax, ay) = axes(px, py, [h, h], [100, 80], 32);
            let v = filter(&ax, &ay, 100, |k| if k % 100 >= edge { 0.0 } else { 1.0 });
            let c = (edge as f64 - px) / h;
            let hidden =
                (c.clamp(-1.0, 1.0).acos() - c * (1.0 - c * c).max(0.0).sqrt()) * FRAC_1_PI;
            assert!(
                (v as f64 - (1.0 - hidden)).abs() < 1e-6,
                "edge {edge}: {v} vs {}",
                1.0 - hidden
            );
        }
    }

    /// Half the ellipse off the map's left edge: half of it outside, lit.
    #[test]
    fn the_part_off_the_map_is_lit() {
        let (ax, ay) = axes(0.0, 40.0, [6.0, 9.0], [100, 80], 16);
        assert!((outside(&ax, &ay) - 0.5).abs() < 1e-12);
        assert!((filter(&ax, &ay, 100, |_| 0.0) - 0.5).abs() < 1e-6);
        let (ax, ay) = axes(f64::NAN, 40.0, [6.0, 9.0], [100, 80], 16);
        assert_eq!(outside(&ax, &ay), 1.0);
        assert_eq!(filter(&ax, &ay, 100, |_| 0.0), 1.0);
    }
}
