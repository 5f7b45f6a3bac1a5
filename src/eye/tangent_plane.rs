//! The part of the light in front of a surface point's tangent plane.
//!
//! Rays from a surface point into its own surface's far side are blocked by
//! that surface right away: the light behind the point's tangent plane is
//! hidden whatever the maps say. The map methods cannot see this (the
//! surface's own micro-patches next to the point are removed by the bias,
//! maps.rs), so the eye view bounds their visibility by the fraction of the
//! light in front of the plane. Points facing away from the whole light get
//! 0 (the far side of a closed mesh, in its own umbra); points facing all
//! of it are untouched.
//!
//! In kernel units the light is the rectangle [-hx, hx] x [-hy, hy] of light
//! points (x, y) (a rectangle's points, or a sun's direction tangents), and
//! the plane's side of a light point is `s(x, y) = a0 + a1 x + a2 y` (the
//! `RayStart::side` coefficients, rays.rs). The fraction with s >= 0 is
//!     (1 / 4 hx hy) ∫_{-hx}^{hx} clamp(hy + (a0 + a1 x) / |a2|, 0, 2 hy) dx
//! (integrating along the axis with the larger coefficient), an integral of
//! a clamped linear function, in closed form.

use super::rays::plane_side;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use glam::DVec3;

/// The fraction of the light in front of the tangent plane at `p` (normal
/// `n`, world; `light` in kernel units, unit-scaled): 0 at or behind a
/// rectangle's plane. The clipping of the light by a plane: each shape its
/// own closed form.
#[inline]
pub fn front_of(space: &LightSpace, unit: f64, light: LightShape, p: DVec3, n: DVec3) -> f64 {
    plane_side(space, unit, p, n).map_or(0.0, |s| match light {
        LightShape::Rect { .. } => front_fraction(s, light.half_extent()),
    })
}

/// ∫_0^t clamp(s, 0, h) ds for any t (the antiderivative of the clamp).
fn clamp_integral(t: f64, h: f64) -> f64 {
    if t <= 0.0 {
        0.0
    } else if t <= h {
        0.5 * t * t
    } else {
        h * t - 0.5 * h * h
    }
}

/// The fraction of the light rectangle [-hx, hx] x [-hy, hy] where
/// a0 + a1 x + a2 y >= 0. A hard light (hx = hy = 0) is its centre.
pub fn front_fraction(side: [f64; 3], half: [f64; 2]) -> f64 {
    let [a0, a1, a2] = side;
    let [hx, hy] = half;
    // Every corner on one side (most points): the whole light or none.
    let reach = a1.abs() * hx + a2.abs() * hy;
    if a0 >= reach {
        return 1.0;
    }
    if a0 < -reach {
        return 0.0;
    }
    if !(hx > 0.0 && hy > 0.0) {
        return if a0 >= 0.0 { 1.0 } else { 0.0 };
    }
    // Integrate along the axis of the smaller coefficient, so the division
    // is by the larger one.
    let (b1, b2, h1, h2) = if a2.abs() >= a1.abs() {
        (a1, a2, hx, hy)
    } else {
        (a2, a1, hy, hx)
    };
    if b2 == 0.0 {
        // Both coefficients are 0: the plane holds the whole light or none.
        return if a0 >= 0.0 { 1.0 } else { 0.0 };
    }
    // len(x) = clamp(h2 + (a0 + b1 x) / |b2|, 0, 2 h2) over x in [-h1, h1].
    let alpha = h2 + a0 / b2.abs();
    let beta = b1 / b2.abs();
    let full = 2.0 * h2;
    let area = if beta.abs() * h1 <= 1e-12 * (alpha.abs() + full) {
        2.0 * h1 * alpha.clamp(0.0, full)
    } else {
        (clamp_integral(alpha + beta * h1, full) - clamp_integral(alpha - beta * h1, full)) / beta
    };
    (area / (4.0 * h1 * h2)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fraction by brute force on a fine grid.
    fn brute(side: [f64; 3], half: [f64; 2]) -> f64 {
        let n = 400;
        let mut k = 0;
        for j in 0..n {
            for i in 0..n {
                let x = (-1.0 + 2.0 * (i as f64 + 0.5) / n as f64) * half[0];
                let y = (-1.0 + 2.0 * (j as f64 + 0.5) / n as f64) * half[1];
                if side[0] + side[1] * x + side[2] * y >= 0.0 {
                    k += 1;
                }
            }
        }
        k as f64 / (n * n) as f64
    }

    #[test]
    fn matches_a_fine_grid() {
        let cases = [
            [0.1, 0.3, -0.7],
            [-0.2, 1.0, 0.2],
            [0.0, 0.0, 1.0],
            [0.5, 0.0, 0.0],
            [-0.5, 0.0, 0.0],
            [0.05, -2.0, 1.9],
            [3.0, 0.1, 0.1],
            [-3.0, 0.1, 0.1],
        ];
        for side in cases {
            for half in [[0.5, 0.5], [1.0, 0.25], [0.01, 0.3]] {
                let (a, b) = (front_fraction(side, half), brute(side, half));
                assert!((a - b).abs() < 6e-3, "{side:?} {half:?}: {a} vs {b}");
            }
        }
        assert_eq!(front_fraction([1.0, 5.0, 5.0], [0.0, 0.0]), 1.0);
        assert_eq!(front_fraction([-1.0, 5.0, 5.0], [0.0, 0.0]), 0.0);
    }
}
