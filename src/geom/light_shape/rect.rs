//! The rectangle's own facts behind `LightShape` (mod.rs): its corners in
//! the world, Lambert's polygon formula for its irradiance with horizon
//! clipping, and the part of it in front of a plane. A new shape is a
//! sibling of this file.
//!
//! **In front of a plane** (the eye view's tangent-plane bound,
//! eye/tangent_plane.rs): in kernel units the light is the rectangle
//! [-hx, hx] x [-hy, hy] of light points (x, y) (a rectangle's points, or a
//! sun's direction tangents), and the plane's side of a light point is
//! `s(x, y) = a0 + a1 x + a2 y`. The fraction with s >= 0 is
//!     (1 / 4 hx hy) ∫_{-hx}^{hx} clamp(hy + (a0 + a1 x) / |a2|, 0, 2 hy) dx
//! (integrating along the axis with the larger coefficient), an integral of
//! a clamped linear function, in closed form.

use super::placement::Placement;
use glam::DVec3;

/// The corners of the rectangle of full `size` placed at `at`,
/// counter-clockwise seen from the side it lights (−u−v, +u−v, +u+v, −u+v).
pub(crate) fn rect_corners(size: [f64; 2], at: &Placement) -> [DVec3; 4] {
    let hu = 0.5 * size[0] * at.u;
    let hv = 0.5 * size[1] * at.v;
    [
        at.center - hu - hv,
        at.center + hu - hv,
        at.center + hu + hv,
        at.center - hu + hv,
    ]
}

/// The unoccluded irradiance at `x` (unit normal `n`) from the rectangle
/// of full `size` and unit radiance placed at `at` (`LightShape::irradiance`).
pub(super) fn irradiance(size: [f64; 2], at: &Placement, x: DVec3, n: DVec3) -> f64 {
    if (x - at.center).dot(at.n) <= 0.0 || size[0] * size[1] == 0.0 {
        return 0.0;
    }
    let p = rect_corners(size, at).map(|c| c - x);
    if p.iter().all(|&q| n.dot(q) >= 0.0) {
        // The whole light above the horizon (most pixels): no clipping.
        return unclipped_quad(&p, n);
    }
    clipped_quad(&p, n)
}

/// `n` turned toward the rectangle of full `size` placed at `at` when its
/// four corners lie strictly on one side of the plane through `p0`
/// (farther than `tol`; `LightShape::strict_side`).
pub(super) fn strict_side(
    size: [f64; 2],
    at: &Placement,
    p0: DVec3,
    n: DVec3,
    tol: f64,
) -> Option<DVec3> {
    let d = rect_corners(size, at).map(|c| n.dot(c - p0));
    if d.iter().all(|&x| x > tol) {
        Some(n)
    } else if d.iter().all(|&x| x < -tol) {
        Some(-n)
    } else {
        None
    }
}

/// The polygon formula for the quad with corners `p` (relative to the
/// point) clipped to the point's upper hemisphere (normal `n`).
fn clipped_quad(p: &[DVec3; 4], n: DVec3) -> f64 {
    // Sutherland–Hodgman against n · p >= 0.
    let mut clipped = [DVec3::ZERO; 8];
    let mut m = 0;
    for i in 0..4 {
        let (a, b) = (p[i], p[(i + 1) % 4]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            clipped[m] = a;
            m += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped[m] = a + (b - a) * (da / (da - db));
            m += 1;
        }
    }
    let mut sum = 0.0;
    for i in 0..m {
        let (a, b) = (clipped[i], clipped[(i + 1) % m]);
        let c = a.cross(b);
        let s = c.length();
        // An edge through x's line of sight (or of no length) subtends no
        // solid angle.
        if s > 0.0 {
            sum += angle(s, a.dot(b)) * n.dot(c) / s;
        }
    }
    (0.5 * sum).max(0.0)
}

/// The polygon formula for a quad wholly above the horizon (corners `p`
/// relative to the point, normal `n`): the same terms as `clipped_quad`'s
/// loop, computed edge by edge into arrays first, so that the four edges'
/// square roots and divisions (the stage's latency, profiled) overlap
/// instead of waiting on the running sum. The code stays scalar; on 300 000
/// points it took 14.3 ms against the shared loop's 16.7 (a one-off timing
/// test, three rounds, 2026-12-03).
#[inline]
#[allow(clippy::needless_range_loop)] // one index over several edge arrays
fn unclipped_quad(p: &[DVec3; 4], n: DVec3) -> f64 {
    let (mut s, mut d, mut nc) = ([0f64; 4], [0f64; 4], [0f64; 4]);
    for i in 0..4 {
        let (a, b) = (p[i], p[(i + 1) % 4]);
        let c = a.cross(b);
        s[i] = c.length_squared();
        d[i] = a.dot(b);
        nc[i] = n.dot(c);
    }
    let mut sum = 0.0;
    for i in 0..4 {
        let len = s[i].sqrt();
        // An edge through the point's line of sight subtends no solid angle.
        let term = angle(len, d[i]) * nc[i] / len;
        sum += if len > 0.0 { term } else { 0.0 };
    }
    (0.5 * sum).max(0.0)
}

/// atan(u) ≈ u · P(u²) on |u| <= tan(π/8): P's coefficients, a minimax
/// fit of degree 4 (iteratively reweighted least squares on 200 001
/// points; the largest error is 7.3e-9, far under the f32 images'
/// resolution; `the_polynomial_angle_matches_atan2_in_every_octant`).
const ATAN_P: [f64; 5] = [
    0.999_999_982_479_900_4,
    -0.333_328_083_409_261_5,
    0.199_747_393_895_807_3,
    -0.138_546_190_472_136_37,
    0.079_941_733_917_503_21,
];

/// `s.atan2(c)` for s >= 0 (an angle in [0, π]) to within 1e-8: the
/// polygon formula takes one per edge and pixel, and libm's atan2 was a
/// third of the shading stage (profiled, 640×480). The octant of (c, s)
/// brings the angle to atan(x/y) with 0 <= x <= y, and atan t = π/4 +
/// atan((t-1)/(t+1)) to an argument within tan(π/8), one division either way.
#[inline(always)]
fn angle(s: f64, c: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let ac = c.abs();
    let swap = s > ac;
    let (x, y) = (if swap { ac } else { s }, if swap { s } else { ac });
    let big = x > (std::f64::consts::SQRT_2 - 1.0) * y;
    let num = if big { x - y } else { x };
    let den = if big { x + y } else { y };
    // den = 0 only where s = c = 0: the angle 0.
    let u = if den > 0.0 { num / den } else { 0.0 };
    let z = u * u;
    let p = ATAN_P[0] + z * (ATAN_P[1] + z * (ATAN_P[2] + z * (ATAN_P[3] + z * ATAN_P[4])));
    // atan(x/y), in [0, π/4].
    let a = if big { FRAC_PI_4 } else { 0.0 } + u * p;
    if swap {
        // |c| < s: θ within π/4 of π/2.
        FRAC_PI_2 - a.copysign(c)
    } else if c >= 0.0 {
        a
    } else {
        PI - a
    }
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
pub(super) fn front_fraction(side: [f64; 3], half: [f64; 2]) -> f64 {
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
    use crate::geom::light::AreaLight;

    /// Irradiance of a unit-radiance rectangle by a midpoint quadrature over
    /// its area, `∫ cos θ_x max(0, cos θ_l) / r² dA` with θ_x clamped at the
    /// horizon.
    fn quadrature(l: &AreaLight, x: DVec3, n: DVec3, k: usize) -> f64 {
        let size = l.shape.extent();
        let area = size[0] * size[1];
        let mut sum = 0.0;
        for i in 0..k {
            for j in 0..k {
                let s = ((i as f64 + 0.5) / k as f64 - 0.5) * size[0];
                let t = ((j as f64 + 0.5) / k as f64 - 0.5) * size[1];
                let d = l.center + s * l.u + t * l.v - x;
                let r2 = d.length_squared();
                let w = d / r2.sqrt();
                let cos_x = n.dot(w).max(0.0);
                let cos_l = (-w).dot(l.n).max(0.0);
                sum += cos_x * cos_l / r2;
            }
        }
        sum * area / (k * k) as f64
    }

    fn light() -> AreaLight {
        AreaLight::rect(
            [0.0, 2.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.6],
        )
        .unwrap()
    }

    #[test]
    fn polygon_formula_matches_quadrature() {
        let l = light();
        let cases = [
            // Under the light, facing it.
            (DVec3::new(0.1, 0.0, -0.2), DVec3::Y),
            // Tilted so that the horizon cuts the light (clipping).
            (
                DVec3::new(0.0, 1.5, 0.0),
                DVec3::new(1.0, 0.3, 0.0).normalize(),
            ),
            (
                DVec3::new(0.4, 1.8, 0.1),
                DVec3::new(-0.2, 0.1, 1.0).normalize(),
            ),
            // Facing away: nothing.
            (DVec3::new(0.0, 0.0, 0.0), -DVec3::Y),
        ];
        for (x, n) in cases {
            let want = quadrature(&l, x, n, 600);
            let got = l.irradiance(x, n);
            assert!(
                (got - want).abs() <= 1e-4 * want.max(1e-2),
                "{x} {n}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn the_polynomial_angle_matches_atan2_in_every_octant() {
        let mut worst = 0f64;
        for i in 0..=20_000 {
            let phi = std::f64::consts::PI * i as f64 / 20_000.0;
            for r in [1e-6, 0.3, 1.0, 7.0, 1e6] {
                let (s, c) = (r * phi.sin().abs(), r * phi.cos());
                worst = worst.max((angle(s, c) - s.atan2(c)).abs());
            }
        }
        assert!(worst < 1e-8, "{worst}");
        assert_eq!(angle(0.0, 0.0), 0.0);
        assert_eq!(angle(0.0, -2.0), std::f64::consts::PI);
        assert_eq!(angle(3.0, 0.0), std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn the_unclipped_fast_path_agrees_with_the_clipping_loop() {
        let l = light();
        let mut checked = 0;
        for i in 0..400 {
            let f = i as f64;
            let x = DVec3::new(
                (f * 0.37).sin() * 3.0,
                (f * 0.11).cos() - 0.5,
                (f * 0.73).sin() * 2.0,
            );
            let n = DVec3::new((f * 1.3).sin() * 0.4, 1.0, (f * 0.7).cos() * 0.4).normalize();
            let p = rect_corners(l.shape.extent(), &l.placement()).map(|c| c - x);
            if p.iter().all(|&q| n.dot(q) >= 0.0) {
                let (fast, general) = (unclipped_quad(&p, n), clipped_quad(&p, n));
                assert!(
                    (fast - general).abs() <= 1e-12 * general.abs(),
                    "{x} {n}: {fast} vs {general}"
                );
                checked += 1;
            }
        }
        assert!(checked > 100, "{checked}");
    }

    #[test]
    fn behind_the_light_and_point_lights_get_nothing() {
        let l = light();
        assert_eq!(l.irradiance(DVec3::new(0.0, 2.5, 0.0), DVec3::Y), 0.0);
        assert_eq!(l.irradiance(DVec3::new(0.0, 2.0, 0.0), -DVec3::Y), 0.0);
        let point =
            AreaLight::rect([0.0; 3], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0]).unwrap();
        assert_eq!(point.irradiance(DVec3::new(0.0, -1.0, 0.0), DVec3::Y), 0.0);
    }

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
