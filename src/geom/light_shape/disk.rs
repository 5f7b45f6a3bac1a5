//! The disk's own facts (a sibling of rect.rs): a one-sided uniform
//! Lambertian disk of radius r in the placement's plane, centred on its
//! centre c, emitting on its +n_l side.
//!
//! **Irradiance** (the eye view's shading). The contour form of Lambert's
//! formula: for a region of unit radiance seen from x (normal n), with p the
//! boundary point relative to x traversed counter-clockwise seen from the
//! lit side (rect.rs's corner order),
//!     E = ∫ cos θ dω = ½ ∮ n · (p × dp) / |p|²,
//! of which the polygon formula is the sum over straight edges. Only the
//! part of the disk above x's horizon (n · p >= 0) counts, so the contour is
//! the boundary of the disk clipped to that half-space: an arc of the circle
//! and, when the horizon cuts the disk, a chord on the tangent plane.
//!
//! In the frame (m, m⊥, n_l), m the in-plane direction from c toward x's
//! foot on the plane (u when x is on the axis) and m⊥ = m × n_l (so
//! m × m⊥ = −n_l, the same turn as u to v in light.rs's left-handed frame),
//! x lies at height h > 0 above the plane and at distance ρ from the axis,
//! and the rim point at angle τ from m is, relative to x,
//!     p(τ) = (r cos τ − ρ, r sin τ, −h).
//! With n = (n_m, n_⊥, n_n) in that frame:
//!     n · (p × p') = −r (r − ρ cos τ) n_n − r h (n_m cos τ + n_⊥ sin τ),
//!     |p|² = h² + (r − ρ)² + 4 r ρ sin²(τ/2),
//! both written so that nothing cancels near the rim point nearest x
//! (τ = 0), where |p| is smallest.
//!
//! * **Horizon.** n · p(τ) = d + ρ_n cos(τ − τ0), d = n · (c − x),
//!   ρ_n = r |(n_m, n_⊥)|, τ0 = atan2(n_⊥, n_m). d >= ρ_n: the whole disk is
//!   above; d <= −ρ_n: none of it; otherwise the arc τ0 ± γ, cos γ = −d/ρ_n,
//!   is above and the chord joins its ends.
//! * **Whole disk** (most points): the contour integral over the full circle
//!   in closed form, the disk's vector irradiance Φ (E = n · Φ),
//!   `Φ = −(π/2)(1 − a/s) n_l − (2π h r² ρ / (s (Z + s))) m`,
//!   with Z = h² + ρ² + r², a = h² + ρ² − r² and
//!   s = √(Z² − 4 r² ρ²) = √((h² + (ρ−r)²)(h² + (ρ+r)²)) (the integrals
//!   ∫ dτ / (Z − 2rρ cos τ) = 2π/s and its cos τ moment); 1 − a/s is taken
//!   as 4 r² h² / (s (s + a)) when a > 0, where the difference would cancel
//!   far from the disk. On the axis facing the disk, E = π r² / (r² + h²).
//! * **Cut by the horizon**: the arc by Gauss–Legendre quadrature and the
//!   chord exactly. The arc's integrand is smooth but peaks at τ = 0 when x
//!   is near the rim (|p|² has complex zeros at τ = ±iη,
//!   η = 2 asinh(δ / 2√(rρ)), δ² = h² + (r − ρ)²): its pieces are graded
//!   geometrically away from τ = 0 ([0, η], then doubling, at most π/4 each),
//!   so every piece sees the pole at least as far away, relatively, as
//!   [0, 1] sees i, and 10 nodes a piece keep the result within ~1e-12 of the
//!   closed form (`graded_arcs_match_the_closed_form`). The chord lies on the
//!   tangent plane, so the plane through x and it is the tangent plane: it
//!   contributes ½ Θ (n · Γ) = ½ Θ, Θ the angle it subtends at x (n · Γ = +1:
//!   n · (a × b) = 2 h r² sin γ / ρ_n > 0 for the chord from the arc's end
//!   a to its start b).
//!
//! **In front of a plane**: the part of the disk with a0 + a1 x + a2 y >= 0
//! is a circular segment; with t = a0 / (r |(a1, a2)|) the centre's signed
//! distance in radii, its fraction is (acos(−t) + t √(1 − t²)) / π.
//!
//! **Clipping a micro-patch**: the area of a rectangle ∩ the disk by
//! inclusion–exclusion of the corner function F(a, b) = area of the disk ∩
//! {X <= a, Y <= b} (`rect_overlap`).
//!
//! **Sampling**: Shirley and Chiu's concentric map (1997) of [0, 1)² onto the
//! disk, area-preserving (Jacobian π r² everywhere), so the strata of a
//! grid keep equal areas on the disk.
// The eye view wires these into `LightShape` next; until then nothing calls
// them outside the tests.
#![allow(dead_code)]

use super::placement::Placement;
use glam::DVec3;
use std::f64::consts::PI;

/// The 10-point Gauss–Legendre rule on [-1, 1]: the positive nodes and their
/// weights (the rule is symmetric), exact for polynomials of degree 19.
const GL_NODES: [f64; 5] = [
    0.148_874_338_981_631_2,
    0.433_395_394_129_247_2,
    0.679_409_568_299_024_4,
    0.865_063_366_688_984_5,
    0.973_906_528_517_171_7,
];
const GL_WEIGHTS: [f64; 5] = [
    0.295_524_224_714_752_9,
    0.269_266_719_309_996_4,
    0.219_086_362_515_982,
    0.149_451_349_150_580_6,
    0.066_671_344_308_688_1,
];

/// The longest quadrature piece (radians of the rim): far from the rim the
/// integrand is nearly a trigonometric polynomial and π/4 a piece is already
/// exact to rounding.
const MAX_PIECE: f64 = PI / 4.0;

/// x seen in the disk's frame (module doc): everything the contour integral
/// needs.
#[derive(Clone, Copy, Debug)]
struct Seen {
    r: f64,
    h: f64,
    rho: f64,
    /// n in (m, m⊥, n_l).
    nm: f64,
    np: f64,
    nn: f64,
}

impl Seen {
    /// `n · (p × p')` over `|p|²` at rim angle τ (the contour integrand).
    #[inline]
    fn integrand(&self, tau: f64) -> f64 {
        let (s, c) = (0.5 * tau).sin_cos();
        let hav = 2.0 * s * s; // 1 − cos τ, without the cancellation near τ = 0
        let (sin_t, cos_t) = (2.0 * s * c, 1.0 - hav);
        let Seen {
            r,
            h,
            rho,
            nm,
            np,
            nn,
        } = *self;
        // r − ρ cos τ = (r − ρ) + ρ (1 − cos τ).
        let num = -r * ((r - rho) + rho * hav) * nn - r * h * (nm * cos_t + np * sin_t);
        let den = h * h + (r - rho) * (r - rho) + 2.0 * r * rho * hav;
        num / den
    }

    /// The rim point at angle τ relative to x, in (m, m⊥, n_l).
    fn rim(&self, tau: f64) -> DVec3 {
        let (s, c) = (0.5 * tau).sin_cos();
        // r cos τ − ρ = (r − ρ) − 2 r sin²(τ/2).
        DVec3::new(
            (self.r - self.rho) - 2.0 * self.r * s * s,
            self.r * 2.0 * s * c,
            -self.h,
        )
    }

    /// The closed form over the whole circle (module doc, "Whole disk").
    fn whole(&self) -> f64 {
        let Seen {
            r, h, rho, nm, nn, ..
        } = *self;
        let z = h * h + rho * rho + r * r;
        // ρ² − r² as a product: near the rim the difference of squares
        // would lose everything but rounding.
        let a = h * h + (rho - r) * (rho + r);
        // s = δ σ, the two factors computed apart (no overflow, no cancellation
        // in Z² − 4 r² ρ²).
        let s = h.hypot(rho - r) * h.hypot(rho + r);
        let axial = if a > 0.0 {
            4.0 * r * r * h * h / (s * (s + a))
        } else {
            (s - a) / s
        };
        let radial = 2.0 * PI * h * r * r * rho / (s * (z + s));
        (-0.5 * PI * axial * nn - radial * nm).max(0.0)
    }

    /// ∫ over the rim angles [lo, hi] (hi − lo <= 2π) of the integrand, by
    /// Gauss–Legendre on pieces graded away from τ = 0 (module doc).
    fn arc(&self, lo: f64, hi: f64) -> f64 {
        // The arc within [−π, π] (the pieces' range): one interval, or two
        // when it wraps past ±π.
        let mut spans = [(lo, hi), (0.0, 0.0)];
        if lo < -PI {
            spans = [(lo + 2.0 * PI, PI), (-PI, hi)];
        } else if hi > PI {
            spans = [(lo, PI), (-PI, hi - 2.0 * PI)];
        }
        // The distance of the integrand's poles from the real axis.
        let delta = self.h.hypot(self.r - self.rho);
        let eta = if self.rho > 0.0 {
            2.0 * (delta / (2.0 * (self.r * self.rho).sqrt())).asinh()
        } else {
            f64::INFINITY
        };
        // A floor that keeps the doubling finite (≈1000 pieces at worst, for
        // a point within 1e-300 of the rim).
        let eta = eta.max(1e-300);
        let mut sum = 0.0;
        let mut a = 0.0;
        while a < PI {
            let step = if a == 0.0 { eta } else { a }.min(MAX_PIECE);
            let b = (a + step).min(PI);
            for (p0, p1) in [(a, b), (-b, -a)] {
                for (s0, s1) in spans {
                    let (x0, x1) = (s0.max(p0), s1.min(p1));
                    if x0 < x1 {
                        sum += self.gauss(x0, x1);
                    }
                }
            }
            a = b;
        }
        sum
    }

    /// The 10-point rule on [a, b].
    fn gauss(&self, a: f64, b: f64) -> f64 {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let mut sum = 0.0;
        for (x, w) in GL_NODES.iter().zip(GL_WEIGHTS) {
            sum += w * (self.integrand(mid - half * x) + self.integrand(mid + half * x));
        }
        sum * half
    }
}

/// The unoccluded irradiance at `x` (unit normal `n`) from the disk of
/// `radius` and unit radiance placed at `at`: ∫ cos θ dω over the part of the
/// disk above x's horizon (module doc); 0 at or behind the light's plane and
/// for radius 0.
pub fn irradiance(radius: f64, at: &Placement, x: DVec3, n: DVec3) -> f64 {
    let rel = x - at.center;
    let h = rel.dot(at.n);
    // `!(.. > 0)` also refuses NaN.
    if !(h > 0.0) || !(radius > 0.0) {
        return 0.0;
    }
    // x's foot on the plane from c, in (u, v): built from u and v so that m
    // lies in the plane even when the offset is rounding noise (on the axis).
    let (fu, fv) = (rel.dot(at.u), rel.dot(at.v));
    let rho = fu.hypot(fv);
    let m = if rho > 0.0 {
        (fu / rho) * at.u + (fv / rho) * at.v
    } else {
        at.u
    };
    let m_perp = m.cross(at.n);
    let seen = Seen {
        r: radius,
        h,
        rho,
        nm: n.dot(m),
        np: n.dot(m_perp),
        nn: n.dot(at.n),
    };
    // n · (c − x) in the same frame as n · p(τ), so that the horizon tests
    // and the arc's ends agree.
    let d = -rho * seen.nm - h * seen.nn;
    let reach = radius * seen.nm.hypot(seen.np);
    if d >= reach {
        return seen.whole();
    }
    if d <= -reach {
        return 0.0;
    }
    // −reach < d < reach, so reach > 0 and the arc is τ0 ± γ, 0 < γ < π.
    let gamma = (-d / reach).clamp(-1.0, 1.0).acos();
    let tau0 = seen.np.atan2(seen.nm);
    let arc = seen.arc(tau0 - gamma, tau0 + gamma);
    // The chord from the arc's end back to its start, on the tangent plane:
    // ½ the angle it subtends (module doc; always counted positive).
    let (a, b) = (seen.rim(tau0 + gamma), seen.rim(tau0 - gamma));
    let chord = a.cross(b).length().atan2(a.dot(b));
    (0.5 * (arc + chord)).max(0.0)
}

/// The fraction of the disk of `radius` (centred at the origin of its plane
/// coordinates) where `side[0] + side[1] x + side[2] y >= 0`: a circular
/// segment (module doc). A disk of radius 0 is its centre.
pub fn front_fraction(side: [f64; 3], radius: f64) -> f64 {
    let [a0, a1, a2] = side;
    let g = a1.hypot(a2) * radius;
    if !(g > 0.0) {
        // A level plane, or a point: the whole disk or none.
        return if a0 >= 0.0 { 1.0 } else { 0.0 };
    }
    let t = a0 / g;
    if t >= 1.0 {
        return 1.0;
    }
    if t <= -1.0 {
        return 0.0;
    }
    ((-t).acos() + t * (1.0 - t * t).sqrt()) / PI
}

/// `nrm` turned toward the disk of `radius` placed at `at` when the whole
/// disk lies strictly on one side of the plane through `p0` with normal
/// `nrm`, farther than `tol`; None when it meets the plane (rect.rs's
/// contract). The disk's signed distances span d_c ± r |nrm's part along
/// the disk's plane|.
pub fn strict_side(radius: f64, at: &Placement, p0: DVec3, nrm: DVec3, tol: f64) -> Option<DVec3> {
    let dc = nrm.dot(at.center - p0);
    let reach = radius * (nrm - nrm.dot(at.n) * at.n).length();
    if dc - reach > tol {
        Some(nrm)
    } else if dc + reach < -tol {
        Some(-nrm)
    } else {
        None
    }
}

/// ∫_{−r}^{a} √(r² − X²) dX for a in [−r, r]: half the area of the disk left
/// of X = a.
fn left_half_area(r: f64, a: f64) -> f64 {
    let a = a.clamp(-r, r);
    // a / r is within [−1, 1] (a is clamped, and rounding is monotone).
    0.5 * (a * (r * r - a * a).max(0.0).sqrt() + r * r * (a / r).asin()) + 0.25 * PI * r * r
}

/// The area of the disk of radius `r` (centred at the origin) with X <= a
/// and Y <= b, for any a, b.
fn corner(r: f64, a: f64, b: f64) -> f64 {
    let a = a.clamp(-r, r);
    if b >= 0.0 {
        // {X <= a} less {X <= a, Y > b}, the mirror image of {X <= a, Y < −b}.
        2.0 * left_half_area(r, a) - corner_below(r, a, -b)
    } else {
        corner_below(r, a, b)
    }
}

/// `corner` for b <= 0: the columns |X| < X_b = √(r² − b²) reach from the
/// rim up to b (height h(X) + b); the others have nothing below b.
fn corner_below(r: f64, a: f64, b: f64) -> f64 {
    let b = b.max(-r);
    let xb = (r * r - b * b).max(0.0).sqrt();
    let a = a.clamp(-xb, xb);
    (left_half_area(r, a) - left_half_area(r, -xb) + b * (a + xb)).max(0.0)
}

/// The area of the rectangle [x0, x1] x [y0, y1] (x0 <= x1, y0 <= y1) within
/// the disk of `radius` centred at the origin: the corner function by
/// inclusion–exclusion, after the rectangle wholly inside or outside (most
/// micro-patches) is answered directly.
pub fn rect_overlap(radius: f64, x: [f64; 2], y: [f64; 2]) -> f64 {
    let r = radius;
    let [x0, x1] = x;
    let [y0, y1] = y;
    if !(r > 0.0) || !(x1 > x0) || !(y1 > y0) {
        return 0.0;
    }
    // The rectangle's farthest and nearest points from the centre.
    let far = x0.abs().max(x1.abs()).hypot(y0.abs().max(y1.abs()));
    if far <= r {
        return (x1 - x0) * (y1 - y0);
    }
    let near = 0f64.clamp(x0, x1).hypot(0f64.clamp(y0, y1));
    if near >= r {
        return 0.0;
    }
    let area = corner(r, x1, y1) - corner(r, x0, y1) - corner(r, x1, y0) + corner(r, x0, y0);
    // Rounding in the differences (of values ~ r²) must not leave the range.
    area.clamp(0.0, ((x1 - x0) * (y1 - y0)).min(PI * r * r))
}

/// The point of stratum (sa, sb) of the a x b grid `grid` on [0, 1)²,
/// jittered by (ja, jb) in [0, 1)², on the disk of `radius`: Shirley and
/// Chiu's concentric map, which is area-preserving, so equal strata cover
/// equal areas of the disk (module doc). The square [−1, 1]² is cut into
/// four wedges by its diagonals; in the wedge |a| > |b| the point is at
/// radius a and angle (π/4)(b/a), in the other at radius b and angle
/// π/2 − (π/4)(a/b).
#[inline(always)]
pub fn sample_point(
    radius: f32,
    grid: (u32, u32),
    sa: u32,
    sb: u32,
    ja: f32,
    jb: f32,
) -> (f32, f32) {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};
    let (na, nb) = grid;
    let a = 2.0 * (sa as f32 + ja) / na as f32 - 1.0;
    let b = 2.0 * (sb as f32 + jb) / nb as f32 - 1.0;
    let (rad, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else if b != 0.0 {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    } else {
        // The square's centre (a = b = 0): the disk's.
        (0.0, 0.0)
    };
    let (s, c) = phi.sin_cos();
    (radius * rad * c, radius * rad * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::light_frame;

    use super::super::test_rng::Rng;

    fn placement(center: [f64; 3], normal: [f64; 3], up: [f64; 3]) -> Placement {
        let (u, v, n) = light_frame("normal", normal, up).unwrap();
        Placement {
            center: DVec3::from_array(center),
            u,
            v,
            n,
        }
    }

    /// A tilted light, off the origin.
    fn tilted() -> Placement {
        placement([0.3, 2.0, -0.4], [0.2, -1.0, 0.3], [0.0, 0.0, 1.0])
    }

    /// The irradiance by a midpoint rule over the disk's area (polar cells
    /// of equal area), `∫ max(0, cos θ_x) cos θ_l / |p|² dA`.
    fn area_quadrature(r: f64, at: &Placement, x: DVec3, n: DVec3, k: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..k {
            let rad = r * ((i as f64 + 0.5) / k as f64).sqrt();
            for j in 0..k {
                let phi = 2.0 * PI * (j as f64 + 0.5) / k as f64;
                let p = at.center + rad * (phi.cos() * at.u + phi.sin() * at.v) - x;
                let r2 = p.length_squared();
                let cos_x = n.dot(p).max(0.0);
                let cos_l = (-p).dot(at.n).max(0.0);
                sum += cos_x * cos_l / (r2 * r2);
            }
        }
        sum * PI * r * r / (k * k) as f64
    }

    /// Lambert's polygon formula for the inscribed regular `k`-gon clipped to
    /// x's upper hemisphere (rect.rs's method for any polygon).
    fn polygon(r: f64, at: &Placement, x: DVec3, n: DVec3, k: usize) -> f64 {
        let p: Vec<DVec3> = (0..k)
            .map(|i| {
                let phi = 2.0 * PI * i as f64 / k as f64;
                at.center + r * (phi.cos() * at.u + phi.sin() * at.v) - x
            })
            .collect();
        let mut clipped = Vec::with_capacity(k + 2);
        for i in 0..k {
            let (a, b) = (p[i], p[(i + 1) % k]);
            let (da, db) = (n.dot(a), n.dot(b));
            if da >= 0.0 {
                clipped.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                clipped.push(a + (b - a) * (da / (da - db)));
            }
        }
        let m = clipped.len();
        let mut sum = 0.0;
        for i in 0..m {
            let (a, b) = (clipped[i], clipped[(i + 1) % m]);
            let c = a.cross(b);
            let s = c.length();
            if s > 0.0 {
                sum += s.atan2(a.dot(b)) * n.dot(c) / s;
            }
        }
        0.5 * sum
    }

    #[test]
    fn the_gauss_legendre_rule_is_exact_to_degree_19() {
        let total: f64 = 2.0 * GL_WEIGHTS.iter().sum::<f64>();
        assert!((total - 2.0).abs() < 1e-15, "{total}");
        for deg in (0..=18).step_by(2) {
            let got: f64 = 2.0
                * GL_NODES
                    .iter()
                    .zip(GL_WEIGHTS)
                    .map(|(x, w)| w * x.powi(deg))
                    .sum::<f64>();
            let want = 2.0 / (deg + 1) as f64;
            assert!((got - want).abs() < 1e-15, "x^{deg}: {got} vs {want}");
        }
    }

    #[test]
    fn on_the_axis_facing_the_disk_it_is_the_closed_form() {
        let at = tilted();
        for (r, h) in [
            (1.0, 1.0),
            (0.5, 3.0),
            (2.0, 0.01),
            (1e-3, 10.0),
            (1.0, 1e-9),
        ] {
            let x = at.center + h * at.n;
            let got = irradiance(r, &at, x, -at.n);
            // π times the form factor r² / (r² + h²).
            let want = PI * r * r / (r * r + h * h);
            assert!(
                (got - want).abs() <= 1e-13 * want,
                "r {r} h {h}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn graded_arcs_match_the_closed_form() {
        // The quadrature over the full circle against the closed form, from
        // far away to within 1e-10 of the rim.
        let mut rng = Rng(7);
        let (mut worst_rel, mut worst_abs) = (0f64, 0f64);
        for i in 0..3000 {
            let r = rng.range(0.1, 3.0);
            let scale = 10f64.powf(rng.range(-10.0, 1.0));
            let (h, rho) = if i % 2 == 0 {
                // Near the rim.
                (scale * rng.next(), r + scale * rng.range(-1.0, 1.0))
            } else {
                (rng.range(1e-3, 5.0), rng.range(0.0, 4.0))
            };
            if !(h > 0.0) || rho < 0.0 {
                continue;
            }
            let n = rng.unit();
            let seen = Seen {
                r,
                h,
                rho,
                nm: n.x,
                np: n.y,
                nn: n.z,
            };
            let quad = 0.5 * seen.arc(-PI, PI);
            // The unclamped closed form (n need not face the disk here).
            let s = h.hypot(rho - r) * h.hypot(rho + r);
            let (z, a) = (h * h + rho * rho + r * r, h * h + (rho - r) * (rho + r));
            let axial = if a > 0.0 {
                4.0 * r * r * h * h / (s * (s + a))
            } else {
                (s - a) / s
            };
            let exact = -0.5 * PI * axial * n.z - 2.0 * PI * h * r * r * rho / (s * (z + s)) * n.x;
            // Relative to the vector irradiance's size where it is not small;
            // absolute where it is (just beside the rim, low, the integrand's
            // O(1) halves cancel to leave ~1e-3, and the error is their
            // rounding).
            let size = 0.5 * PI * axial + 2.0 * PI * h * r * r * rho / (s * (z + s));
            let err = (quad - exact).abs();
            worst_abs = worst_abs.max(err);
            if size > 0.1 {
                worst_rel = worst_rel.max(err / size);
            }
        }
        eprintln!("graded arcs: relative {worst_rel:e}, absolute {worst_abs:e}");
        assert!(worst_rel < 1e-12, "{worst_rel}");
        assert!(worst_abs < 1e-13, "{worst_abs}");
    }

    #[test]
    fn matches_the_clipped_polygon_formula() {
        // Lambert's formula on a 2^17-gon (its area within ~4e-10 of the
        // disk's), at random points and normals, many cut by the horizon.
        let at = tilted();
        let mut rng = Rng(11);
        let (mut worst, mut cut) = (0f64, 0);
        for _ in 0..60 {
            let r = rng.range(0.2, 1.5);
            let h = 10f64.powf(rng.range(-2.0, 0.7));
            let rho = rng.range(0.0, 2.5);
            let phi = rng.range(0.0, 2.0 * PI);
            let x = at.center + h * at.n + rho * (phi.cos() * at.u + phi.sin() * at.v);
            let mut n = rng.unit();
            if n.dot(at.center - x) < 0.0 && rng.next() < 0.8 {
                n = -n;
            }
            let got = irradiance(r, &at, x, n);
            let want = polygon(r, &at, x, n, 1 << 17);
            let d = n.dot(at.center - x);
            let reach = r * (n - n.dot(at.n) * at.n).length();
            cut += usize::from(d.abs() < reach);
            worst = worst.max((got - want).abs() / want.max(1e-3));
        }
        eprintln!("clipped polygon: {cut} of 60 cut, relative {worst:e}");
        assert!(cut > 20, "{cut}");
        assert!(worst < 5e-9, "{worst}");
    }

    #[test]
    fn matches_an_area_quadrature() {
        let at = tilted();
        let r = 0.7;
        let c = at.center;
        let cases = [
            // Facing the disk, off axis.
            (c + 0.8 * at.n + 0.3 * at.u, -at.n),
            // Cut by the horizon.
            (c + 0.5 * at.n + 0.2 * at.v, (at.u - 0.3 * at.n).normalize()),
            (
                c + 1.2 * at.n - 0.9 * at.u + 0.4 * at.v,
                (0.6 * at.u + 0.2 * at.v - 0.4 * at.n).normalize(),
            ),
            // Beside the disk, tilted toward it.
            (
                c + 0.3 * at.n + 1.5 * at.u,
                (-at.u - 0.2 * at.n).normalize(),
            ),
            // Nearly edge-on.
            (c + 0.6 * at.n, (at.v - 0.01 * at.n).normalize()),
        ];
        let mut worst = 0f64;
        for (x, n) in cases {
            let got = irradiance(r, &at, x, n);
            let want = area_quadrature(r, &at, x, n, 1500);
            assert!(want > 1e-3, "{want}");
            worst = worst.max((got - want).abs() / want);
        }
        eprintln!("disk area quadrature: relative {worst:e}");
        assert!(worst < 1e-5, "{worst}");
    }

    #[test]
    fn degenerate_points_give_finite_continuous_values() {
        let at = tilted();
        let r = 1.0;
        let c = at.center;
        // Behind or on the plane, radius 0, facing away: nothing. (The plane
        // Z = 0 with its centre at the origin, where a point's height is
        // exact.)
        let flat = placement([0.0; 3], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
        let z = DVec3::Z;
        assert_eq!(irradiance(r, &at, c - 0.5 * at.n, at.n), 0.0);
        assert_eq!(irradiance(r, &flat, DVec3::new(0.3, 0.2, 0.0), -z), 0.0);
        assert_eq!(irradiance(r, &flat, DVec3::new(0.3, 0.2, -0.0), z), 0.0);
        assert_eq!(irradiance(0.0, &at, c + at.n, -at.n), 0.0);
        assert_eq!(irradiance(r, &at, c + at.n, at.n), 0.0);
        // Very close to the plane: above the disk, facing it, E -> π; on the
        // rim, π/2 (half the view is the disk); at any tilt, in [0, π].
        for h in [1e-300, 1e-15, 1e-12, 1e-8, 1e-4] {
            let above = irradiance(r, &flat, DVec3::new(0.0, 0.5, h), -z);
            assert!((above - PI).abs() <= 1e-13 + 2.0 * h, "{h}: {above}");
            let rim = irradiance(r, &flat, DVec3::new(r, 0.0, h), -z);
            assert!((rim - 0.5 * PI).abs() <= 1e-13 + 2.0 * h, "{h}: {rim}");
            for k in 0..50 {
                let t = k as f64 / 49.0;
                let n = ((1.0 - t) * -z + t * DVec3::new(1.0, 0.3, 0.0)).normalize();
                for rho in [0.0, 0.5, 1.0 - 1e-9, 1.0, 1.0 + 1e-9, 2.0] {
                    for x in [DVec3::new(rho, 0.0, h), DVec3::new(-rho, 0.1, h)] {
                        let e = irradiance(r, &flat, x, n);
                        assert!(e.is_finite() && (0.0..=PI + 1e-12).contains(&e), "{e}");
                    }
                }
            }
        }
        // Continuity where the horizon starts to cut the disk (d = reach:
        // the closed form on one side, the clipped arc on the other) and
        // where it leaves it (d = −reach: E -> 0).
        let x = c + 0.7 * at.n + 0.4 * at.u;
        for dir in [at.u, at.v, -at.u, (at.u - at.v).normalize()] {
            // n = cos ψ (−n_l) + sin ψ dir, from facing the disk (ψ = 0) to
            // facing away (ψ = π); the transitions by bisection.
            let nrm = |psi: f64| psi.cos() * -at.n + psi.sin() * dir;
            let gap = |psi: f64, side: f64| {
                let n = nrm(psi);
                n.dot(c - x) + side * r * (n - n.dot(at.n) * at.n).length()
            };
            let edge = |side: f64, mut lo: f64, mut hi: f64| {
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if gap(mid, side) > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                (lo, hi)
            };
            let (lo, hi) = edge(-1.0, 0.0, 0.5 * PI);
            let (a, b) = (
                irradiance(r, &at, x, nrm(lo - 1e-9)),
                irradiance(r, &at, x, nrm(hi + 1e-9)),
            );
            assert!((a - b).abs() < 1e-8 * a, "{dir}: {a} vs {b}");
            let (lo, hi) = edge(1.0, 0.5 * PI, PI);
            let (a, b) = (
                irradiance(r, &at, x, nrm(lo - 1e-6)),
                irradiance(r, &at, x, nrm(hi + 1e-6)),
            );
            assert!(a > 0.0 && a < 1e-8 && b == 0.0, "{dir}: {a} vs {b}");
        }
    }

    #[test]
    fn front_fraction_matches_a_fine_grid() {
        let brute = |side: [f64; 3], r: f64| {
            let k = 800;
            let (mut inside, mut front) = (0usize, 0usize);
            for j in 0..k {
                for i in 0..k {
                    let x = (-1.0 + 2.0 * (i as f64 + 0.5) / k as f64) * r;
                    let y = (-1.0 + 2.0 * (j as f64 + 0.5) / k as f64) * r;
                    if x * x + y * y <= r * r {
                        inside += 1;
                        front += usize::from(side[0] + side[1] * x + side[2] * y >= 0.0);
                    }
                }
            }
            front as f64 / inside as f64
        };
        let mut worst = 0f64;
        for side in [
            [0.1, 0.3, -0.7],
            [-0.2, 1.0, 0.2],
            [0.0, 0.0, 1.0],
            [0.05, -2.0, 1.9],
            [3.0, 0.1, 0.1],
            [-3.0, 0.1, 0.1],
            [0.4, 0.0, -1.0],
        ] {
            for r in [0.5, 1.0, 0.05] {
                let (a, b) = (front_fraction(side, r), brute(side, r));
                worst = worst.max((a - b).abs());
            }
        }
        eprintln!("front fraction vs grid: {worst:e}");
        assert!(worst < 5e-4, "{worst}");
        assert_eq!(front_fraction([0.5, 0.0, 0.0], 1.0), 1.0);
        assert_eq!(front_fraction([-0.5, 0.0, 0.0], 1.0), 0.0);
        assert_eq!(front_fraction([0.0, 0.0, 0.0], 1.0), 1.0);
        assert_eq!(front_fraction([1.0, 5.0, 5.0], 0.0), 1.0);
        assert_eq!(front_fraction([-1.0, 5.0, 5.0], 0.0), 0.0);
        assert!((front_fraction([0.0, 1.0, -2.0], 1.0) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn strict_side_matches_the_rim() {
        let at = tilted();
        let mut rng = Rng(3);
        let r = 0.8;
        for _ in 0..2000 {
            let p0 = at.center
                + 1.5
                    * DVec3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    );
            let nrm = rng.unit();
            let tol = rng.range(0.0, 0.1);
            let d: Vec<f64> = (0..720)
                .map(|i| {
                    let phi = 2.0 * PI * i as f64 / 720.0;
                    nrm.dot(at.center + r * (phi.cos() * at.u + phi.sin() * at.v) - p0)
                })
                .collect();
            let (lo, hi) = d
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            let got = strict_side(r, &at, p0, nrm, tol);
            // Away from the threshold (the rim sampled every 0.5°).
            let slack = 1e-4 * r;
            if lo > tol + slack {
                assert_eq!(got, Some(nrm));
            } else if hi < -tol - slack {
                assert_eq!(got, Some(-nrm));
            } else if lo < tol - slack && hi > -tol + slack {
                assert_eq!(got, None);
            }
        }
    }

    /// The overlap by a fine midpoint grid over the rectangle.
    fn overlap_grid(r: f64, x: [f64; 2], y: [f64; 2], k: usize) -> f64 {
        let mut inside = 0usize;
        for j in 0..k {
            for i in 0..k {
                let px = x[0] + (x[1] - x[0]) * (i as f64 + 0.5) / k as f64;
                let py = y[0] + (y[1] - y[0]) * (j as f64 + 0.5) / k as f64;
                inside += usize::from(px * px + py * py <= r * r);
            }
        }
        inside as f64 * (x[1] - x[0]) * (y[1] - y[0]) / (k * k) as f64
    }

    #[test]
    fn rect_overlap_matches_a_fine_grid() {
        let r = 1.3;
        assert!((rect_overlap(r, [-r, r], [-r, r]) - PI * r * r).abs() < 1e-14);
        assert!((rect_overlap(r, [-5.0, 5.0], [-7.0, 9.0]) - PI * r * r).abs() < 1e-14);
        assert!((rect_overlap(r, [0.0, 5.0], [0.0, 5.0]) - 0.25 * PI * r * r).abs() < 1e-14);
        assert!((rect_overlap(r, [-5.0, 5.0], [-7.0, 0.0]) - 0.5 * PI * r * r).abs() < 1e-14);
        // Wholly inside, wholly outside, empty.
        assert_eq!(rect_overlap(r, [-0.2, 0.3], [0.1, 0.5]), 0.5 * 0.4);
        assert_eq!(rect_overlap(r, [1.0, 2.0], [1.0, 2.0]), 0.0);
        assert_eq!(rect_overlap(r, [-3.0, 3.0], [1.3, 2.0]), 0.0);
        assert_eq!(rect_overlap(r, [0.2, 0.2], [0.0, 1.0]), 0.0);
        assert_eq!(rect_overlap(0.0, [-1.0, 1.0], [-1.0, 1.0]), 0.0);
        let mut rng = Rng(5);
        let mut worst = 0f64;
        for i in 0..300 {
            // Rectangles of every size, many straddling the rim.
            let size = if i % 3 == 0 { 1e-2 } else { 1.5 };
            let cx = rng.range(-1.8, 1.8);
            let cy = rng.range(-1.8, 1.8);
            let (w, h) = (size * rng.next(), size * rng.next());
            let (x, y) = ([cx - w, cx + w], [cy - h, cy + h]);
            let got = rect_overlap(r, x, y);
            let want = overlap_grid(r, x, y, 1000);
            let area = 4.0 * w * h;
            worst = worst.max((got - want).abs() / area);
            assert!(got >= 0.0 && got <= area + 1e-15);
        }
        // A 1000² grid resolves a rim crossing to ~1e-4 of the rectangle.
        eprintln!("rect overlap vs grid: {worst:e} of the rectangle");
        assert!(worst < 5e-4, "{worst}");
        // Nested boxes add up: four quadrants make the whole.
        let (x, y) = ([-0.9, 1.1], [-1.2, 0.4]);
        let whole = rect_overlap(r, x, y);
        let parts = rect_overlap(r, [x[0], 0.3], [y[0], -0.1])
            + rect_overlap(r, [0.3, x[1]], [y[0], -0.1])
            + rect_overlap(r, [x[0], 0.3], [-0.1, y[1]])
            + rect_overlap(r, [0.3, x[1]], [-0.1, y[1]]);
        assert!((whole - parts).abs() < 1e-14, "{whole} vs {parts}");
    }

    #[test]
    fn concentric_samples_are_inside_and_strata_have_equal_areas() {
        let radius = 1.7f32;
        for grid in [(4, 4), (7, 5), (1, 1), (16, 9)] {
            let (na, nb) = grid;
            let want = PI * (radius as f64).powi(2) / (na * nb) as f64;
            let mut total = 0.0;
            for sa in 0..na {
                for sb in 0..nb {
                    // The image of the stratum's boundary, counter-clockwise,
                    // its area by the shoelace formula.
                    let k = 256;
                    let mut pts = Vec::with_capacity(4 * k);
                    for e in 0..4 {
                        for i in 0..k {
                            let t = i as f32 / k as f32;
                            let (ja, jb) = match e {
                                0 => (t, 0.0),
                                1 => (1.0, t),
                                2 => (1.0 - t, 1.0),
                                _ => (0.0, 1.0 - t),
                            };
                            let (x, y) = sample_point(radius, grid, sa, sb, ja, jb);
                            pts.push((x as f64, y as f64));
                        }
                    }
                    let mut area = 0.0;
                    for i in 0..pts.len() {
                        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                        area += 0.5 * (a.0 * b.1 - b.0 * a.1);
                    }
                    assert!(
                        (area - want).abs() < 2e-4 * want,
                        "{grid:?} ({sa}, {sb}): {area} vs {want}"
                    );
                    total += area;
                }
            }
            let disk = PI * (radius as f64).powi(2);
            assert!((total - disk).abs() < 1e-4 * disk, "{total} vs {disk}");
        }
        // Every jittered sample is inside the disk.
        let mut rng = Rng(9);
        let top = 1.0f32 - f32::EPSILON / 2.0;
        for i in 0..100_000 {
            let (ja, jb) = match i {
                0 => (top, top),
                1 => (0.0, top),
                2 => (top, 0.0),
                _ => (rng.next() as f32, rng.next() as f32),
            };
            let grid = (1 + (i % 7) as u32, 1 + (i % 5) as u32);
            let (sa, sb) = (grid.0 - 1 - (i % 2) as u32 * (grid.0 - 1), grid.1 - 1);
            let (x, y) = sample_point(radius, grid, sa, sb, ja, jb);
            let r = (x as f64).hypot(y as f64);
            assert!(r <= radius as f64 * (1.0 + 1e-6), "{r}");
        }
        assert_eq!(sample_point(1.0, (2, 2), 1, 1, 0.0, 0.0), (0.0, 0.0));
    }
}
