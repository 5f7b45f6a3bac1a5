//! PCSS's weighted visibility: the filter's cells weighted by their share
//! of a Lambertian receiver's irradiance, for the eye view's shaded image
//! (eye/shading.rs): the ratio estimator of Heitz, Hill & McGuire 2018
//! ("Combining analytic direct illumination and stochastic shadows", §3)
//! with PCSS's filtered visibility in place of V.
//!
//! Maths. PCSS filters the occluders as if all were at the blockers' mean
//! depth z_avg, through the map l -> t_r + l (1/z_avg - 1/z_r) (pcss.rs's
//! module doc): a scaling that takes the light onto the filter box (under
//! a disk, onto the ellipse inscribed in it). So a cell of the box at
//! pixel offset (u, v) = ((x - px)/hx, (y - py)/hy) from the receiver
//! stands for the light point l = (u Lx/2, -v Ly/2) (rows run down, the
//! tangent's y up: `MapGrid::to_pixel`). A receiver p with normal n weighs
//! the light point l by w(l) = cos θ cos θ' / r² (`SurfacePoint::weight`).
//! With each cell's share a_c (its part of the box, or its overlap with
//! the ellipse: the plain filter's weights) and its texels' tests,
//!
//! ```text
//!     H_w = Σ_c a_c (1 - lit_c) w(l_c) / (Σ_c a_c + out),
//!     V_w = 1 - min(H_w / w̄, 1),     w̄ = (∫ w dA) / |light|,
//! ```
//!
//! `out` the filter's part off the map (lit, as in the plain filter), l_c
//! the cell's centre (the midpoint rule on each cell, as the SSM's
//! micro-patches in `ssm/weighted.rs`), w̄ the mean weight over the light
//! (a quarter of `shadow_rays::light_weight`). With every weight equal
//! this is the plain filter's 1 - V. A point whose plain visibility is 0
//! or 1 keeps it (the shading then needs no weights).
//!
//! Where the box's half-width is raised to half a texel (pcf.rs) its cells
//! stand for more than the light; the light is then under a texel wide in
//! the map, and its weights change little across it.

use super::pcf::Axis;
use super::pcf_disk;
use crate::geom::light_shape::disk::rect_overlap;
use crate::trace::shadow_rays::{light_weight, SurfacePoint};
use std::f64::consts::FRAC_1_PI;

/// The receiver a weighted filter weighs for: its surface point and the
/// light's half-extents (kernel units).
#[derive(Debug, Clone, Copy)]
pub(super) struct Weigh {
    pub surface: SurfacePoint,
    pub half: [f32; 2],
}

/// The weighted visibility (module doc) of a point whose plain filter over
/// the axes `ax` x `ay` (the filter box; under a `disk`, its ellipse) gave
/// `v`, its texels' tests `lit(k)` (1 lit, 0 shadowed).
pub(super) fn weighted_visibility(
    v: f32,
    ax: &Axis,
    ay: &Axis,
    width: usize,
    disk: bool,
    lit: impl Fn(usize) -> f32,
    weigh: &Weigh,
) -> f32 {
    if !(v > 0.0 && v < 1.0) {
        return v;
    }
    let half = weigh.half.map(f64::from);
    let (px, hx) = ax.centre_half();
    let (py, hy) = ay.centre_half();
    let (mut hidden, mut den) = (0f64, 0f64);
    ay.cells(|y0, y1, ry| {
        let vs = [(y0 - py) / hy, (y1 - py) / hy];
        if disk && (vs[0] >= 1.0 || vs[1] <= -1.0) {
            return;
        }
        let ly = (-0.5 * (vs[0] + vs[1]) * half[1]) as f32;
        ax.cells(|x0, x1, rx| {
            let us = [(x0 - px) / hx, (x1 - px) / hx];
            let a = if disk {
                rect_overlap(1.0, us, vs) * FRAC_1_PI
            } else {
                0.25 * (us[1] - us[0]) * (vs[1] - vs[0])
            };
            if !(a > 0.0) {
                return;
            }
            let (mut read, mut shadowed) = (0f64, 0f64);
            for &(j, fy) in ry {
                for &(i, fx) in rx {
                    let f = fy * fx;
                    read += f;
                    shadowed += f * f64::from(1.0 - lit(j * width + i));
                }
            }
            den += a * read;
            if shadowed > 0.0 {
                let lx = (0.5 * (us[0] + us[1]) * half[0]) as f32;
                hidden += a * shadowed * f64::from(weigh.surface.weight(lx, ly));
            }
        });
    });
    den += if disk {
        pcf_disk::outside(ax, ay)
    } else {
        let (ox, oy) = (ax.outside(), ay.outside());
        (ox + oy - ox * oy).clamp(0.0, 1.0)
    };
    let mean = 0.25 * light_weight(&weigh.surface, weigh.half, disk);
    if !(mean > 0.0) {
        // The whole light behind the tangent plane: no irradiance to share.
        return 0.0;
    }
    if !(den > 0.0) {
        return v;
    }
    (1.0 - (hidden / den / mean).clamp(0.0, 1.0)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn axes(p: [f64; 2], h: [f64; 2], n: [usize; 2], taps: u32) -> (Axis, Axis) {
        (
            Axis::new(p[0], h[0], n[0], taps, false),
            Axis::new(p[1], h[1], n[1], taps, false),
        )
    }

    /// A receiver right under the light's centre, facing it, at depth 1:
    /// w(l) = 1 / (1 + |l|²)², largest at the centre.
    fn under_the_centre(half: [f32; 2]) -> Weigh {
        Weigh {
            surface: SurfacePoint {
                p: Vec3::new(0.0, 0.0, 1.0),
                // n = -Z (toward the light): side(x, y) = p_z.
                side: [1.0, 0.0, 0.0],
            },
            half,
        }
    }

    /// Uniform weights (a light far away) give the plain filter back; a
    /// near light's centre weighs more than its rim, so a shadow over the
    /// centre hides more than its area and one over the rim less.
    #[test]
    fn weights_move_the_visibility_toward_the_lights_centre() {
        let n = [64, 64];
        for (disk, taps) in [(false, 64), (false, 7), (true, 64), (true, 7)] {
            let (ax, ay) = axes([32.0, 32.0], [16.0, 16.0], n, taps);
            // The texels within 6 of the centre column hide a central band.
            let band = |k: usize| if (k % 64).abs_diff(32) < 6 { 0f32 } else { 1.0 };
            let rim = |k: usize| if k % 64 >= 40 { 0f32 } else { 1.0 };
            let plain = |lit: &dyn Fn(usize) -> f32| {
                if disk {
                    pcf_disk::filter(&ax, &ay, 64, lit)
                } else {
                    let mut s = 0.0;
                    super::super::pcf::visit(&ax, &ay, 64, |k, w| s += w * lit(k) as f64);
                    s as f32
                }
            };
            let far = under_the_centre([1e-3, 1e-3]);
            let near = under_the_centre([1.0, 1.0]);
            for (name, lit) in [("band", &band as &dyn Fn(usize) -> f32), ("rim", &rim)] {
                let v = plain(lit);
                assert!(v > 0.1 && v < 0.9, "{name}: {v}");
                let w_far = weighted_visibility(v, &ax, &ay, 64, disk, lit, &far);
                let w_near = weighted_visibility(v, &ax, &ay, 64, disk, lit, &near);
                eprintln!("{disk} {taps} {name}: plain {v}, far {w_far}, near {w_near}");
                assert!((w_far - v).abs() < 1e-4, "{name}: {w_far} vs {v}");
                if name == "band" {
                    assert!(w_near < v - 0.02, "{name}: {w_near} vs {v}");
                } else {
                    assert!(w_near > v + 0.02, "{name}: {w_near} vs {v}");
                }
            }
            // 0 and 1 are kept.
            assert_eq!(
                weighted_visibility(1.0, &ax, &ay, 64, disk, |_| 0.0, &near),
                1.0
            );
            assert_eq!(
                weighted_visibility(0.0, &ax, &ay, 64, disk, |_| 1.0, &near),
                0.0
            );
        }
    }
}
