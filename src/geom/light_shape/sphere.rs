//! The sphere's own facts (a sibling of rect.rs and disk.rs): a uniform
//! spherical emitter of radius R centred at c. Seen from a point x outside
//! it, at distance D = |c − x|, it fills the cap of directions within the
//! angle α of w = (c − x)/D, sin α = R/D, of solid angle
//! Ω = 2π (1 − cos α) (every direction of the cap meets the sphere, and the
//! radiance along it is the sphere's, whatever the point hit).
//!
//! **Irradiance** of unit radiance, E = ∫_cap max(0, cos θ) dω with
//! cos θ = n · ω, β the angle between n and w:
//! * wholly above the horizon (β <= π/2 − α, i.e. cos β >= sin α): the cap's
//!   mean of ω is (1 + cos α)/2 w and E = Ω (1 + cos α)/2 cos β
//!   = π sin²α cos β (the point-light law at the centre, exact for a sphere);
//! * wholly below (cos β <= −sin α): 0;
//! * cut by the horizon: the closed form for a horizon-clipped spherical cap
//!   (Snyder 1996, "Area light sources for real-time graphics", Microsoft
//!   Research MSR-TR-96-11; in Lagarde and de Rousiers 2014, "Moving
//!   Frostbite to PBR", §4.7.2, `illuminanceSphereOrDisk`),
//!   `E = sin²α (cos β acos y − x sin β √(1 − y²)) + atan(sin β √(1 − y²) / x)`,
//!   x = cot α, y = −x cot β. At cos β = ±sin α it meets the other two
//!   cases (y = ∓1). Its two terms are each ~α and leave ~α³ for a small
//!   sphere (in f64 it erred 6e-11 relative at sin α = 1e-3, 5e-7 at 1e-5),
//!   so it is evaluated rearranged: with z = sin β √(1 − y²) tan α (the
//!   atan's argument), x sin²α sin β √(1 − y²) = z cos²α = z − z sin²α, and
//!   `E = sin²α (cos β acos y + z) + (atan z − z)`, where atan z − z is
//!   summed as its series for small z and nothing cancels
//!   (`small_spheres_keep_their_digits`).
//!
//! **Sampling** (the eye view's rays): directions uniform in solid angle on
//! the cap, cos θ = 1 − u1 (1 − cos α), φ = 2π u2 about w, and the distance
//! along each to the sphere's near surface.
//!
//! 1 − cos α is taken as sin²α / (1 + cos α) throughout, exact for a far,
//! small sphere where 1 − cos α would round to nothing.
// The eye view wires these into `LightShape` next; until then nothing calls
// them outside the tests.
#![allow(dead_code)]

use glam::DVec3;
use std::f64::consts::PI;

/// The cap seen from `x`: (w, D, sin²α, cos α), None when x is inside or on
/// the sphere (or the radius is not > 0).
#[inline]
fn cap(center: DVec3, radius: f64, x: DVec3) -> Option<(DVec3, f64, f64, f64)> {
    let q = center - x;
    let d2 = q.length_squared();
    let r2 = radius * radius;
    // `!(.. > ..)` also refuses NaN.
    if !(radius > 0.0) || !(d2 > r2) {
        return None;
    }
    let d = d2.sqrt();
    Some((q / d, d, r2 / d2, (d2 - r2).sqrt() / d))
}

/// atan z − z, without the cancellation for small z: the alternating series
/// −z³/3 + z⁵/5 − … for |z| < 1/4 (its terms shrink by z² <= 1/16, so 14
/// of them reach the rounding), the difference itself above (no worse than
/// a factor 50 of cancellation there).
fn atan_minus_identity(z: f64) -> f64 {
    if z.abs() >= 0.25 {
        return z.atan() - z;
    }
    let z2 = z * z;
    let mut term = -z * z2;
    let mut sum = 0.0;
    for k in 1..=14 {
        sum += term / (2 * k + 1) as f64;
        term *= -z2;
    }
    sum
}

/// The unoccluded irradiance at `x` (unit normal `n`) from the sphere of
/// `radius` and unit radiance centred at `center`: ∫ max(0, cos θ) dω over
/// its cap (module doc); 0 when x is inside or on the sphere (callers refuse
/// such points) and for radius 0.
pub fn irradiance(center: DVec3, radius: f64, x: DVec3, n: DVec3) -> f64 {
    let Some((w, _, sin2, cos_a)) = cap(center, radius, x) else {
        return 0.0;
    };
    let sin_a = sin2.sqrt();
    let cos_b = n.dot(w).clamp(-1.0, 1.0);
    if cos_b >= sin_a {
        return PI * sin2 * cos_b;
    }
    if cos_b <= -sin_a {
        return 0.0;
    }
    // |cos β| < sin α < 1 here, so sin β > 0; cos α > 0 since D > R.
    let sin_b = (1.0 - cos_b * cos_b).sqrt();
    let cot_a = cos_a / sin_a;
    let y = (-cot_a * cos_b / sin_b).clamp(-1.0, 1.0);
    let z = sin_b * (1.0 - y * y).max(0.0).sqrt() * (sin_a / cos_a);
    let e = sin2 * (cos_b * y.acos() + z) + atan_minus_identity(z);
    // A cos α that underflowed would make z infinite: the cap is then the
    // half-space of directions and E its limit.
    if e.is_finite() {
        e.max(0.0)
    } else {
        0.0
    }
}

/// The solid angle of the cap seen from `x`, 2π (1 − cos α); 0 when x is
/// inside or on the sphere (callers refuse such points).
pub fn cap_solid_angle(center: DVec3, radius: f64, x: DVec3) -> f64 {
    match cap(center, radius, x) {
        Some((_, _, sin2, cos_a)) => 2.0 * PI * sin2 / (1.0 + cos_a),
        None => 0.0,
    }
}

/// The unit direction from `x` of the cap sample (u1, u2) in [0, 1)²,
/// uniform in solid angle: cos θ = 1 − u1 (1 − cos α) from w, φ = 2π u2
/// about it. None when x is inside or on the sphere.
pub fn cap_direction(center: DVec3, radius: f64, x: DVec3, u1: f64, u2: f64) -> Option<DVec3> {
    let (w, _, sin2, cos_a) = cap(center, radius, x)?;
    // t = 1 − cos θ, and sin θ = √(t (2 − t)) (no cancellation near w).
    let t = u1 * sin2 / (1.0 + cos_a);
    let sin_t = (t * (2.0 - t)).max(0.0).sqrt();
    let (e1, e2) = w.any_orthonormal_pair();
    let (s, c) = (2.0 * PI * u2).sin_cos();
    Some((1.0 - t) * w + sin_t * (c * e1 + s * e2))
}

/// The distance from `x` along the unit direction `dir` to the sphere's near
/// surface. For a direction in the cap it is b − √(R² − |q − b dir|²)
/// (q = c − x, b = q · dir), taken as (D² − R²) / (b + √…) so that nothing
/// cancels when the sphere is small and far; a ray that grazes (the root
/// rounded negative, at the cap's edge) is clamped to the tangent point's
/// distance √(D² − R²) or near it, so every direction of the cap gets a
/// finite distance. A direction pointing away from the sphere (b <= 0) gets
/// infinity, and a point inside or on the sphere 0.
/// The cap seen from a point, set up once for many directions
/// (`cap_direction`'s frame and scale): the axis w toward the centre, an
/// orthonormal pair about it, and 1 − cos α.
#[derive(Clone, Copy, Debug)]
pub struct CapFrame {
    w: DVec3,
    e1: DVec3,
    e2: DVec3,
    one_minus_cos_a: f64,
}

impl CapFrame {
    /// The frame of the cap seen from `x`; None inside the sphere.
    pub fn new(center: DVec3, radius: f64, x: DVec3) -> Option<CapFrame> {
        let (w, _, sin2, cos_a) = cap(center, radius, x)?;
        let (e1, e2) = w.any_orthonormal_pair();
        Some(CapFrame {
            w,
            e1,
            e2,
            one_minus_cos_a: sin2 / (1.0 + cos_a),
        })
    }

    /// The axis w, the pair (e1, e2) about it, and 1 − cos α: what the
    /// GPU's twin of `direction` reads (gpu/sphere_rays.wgsl).
    pub fn parts(&self) -> ([DVec3; 3], f64) {
        ([self.w, self.e1, self.e2], self.one_minus_cos_a)
    }

    /// `cap_direction` with u1 and the azimuth's cosine and sine given:
    /// cos θ = 1 − u1 (1 − cos α).
    #[inline]
    pub fn direction(&self, u1: f64, cos_phi: f64, sin_phi: f64) -> DVec3 {
        let t = u1 * self.one_minus_cos_a;
        let sin_t = (t * (2.0 - t)).max(0.0).sqrt();
        (1.0 - t) * self.w + sin_t * (cos_phi * self.e1 + sin_phi * self.e2)
    }
}

pub fn cap_hit(center: DVec3, radius: f64, x: DVec3, dir: DVec3) -> f64 {
    let q = center - x;
    let d2 = q.length_squared();
    let r2 = radius * radius;
    if !(d2 > r2) {
        return 0.0;
    }
    let b = q.dot(dir);
    if !(b > 0.0) {
        return f64::INFINITY;
    }
    // R² − (distance from c to the ray's line)², clamped at a graze.
    let disc = (r2 - (q - b * dir).length_squared()).max(0.0);
    (d2 - r2) / (b + disc.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::super::test_rng::Rng;

    /// Snyder's form as published (module doc), for comparison.
    fn snyder(sin2: f64, cos_b: f64) -> f64 {
        let sin_b = (1.0 - cos_b * cos_b).sqrt();
        let x = (1.0 / sin2 - 1.0).sqrt();
        let y = -x * cos_b / sin_b;
        let sy = sin_b * (1.0 - y * y).sqrt();
        (cos_b * y.acos() - x * sy) * sin2 + (sy / x).atan()
    }

    /// E by a midpoint rule over the cap's solid angle in (cos θ, φ) about
    /// w, `∫ max(0, n · ω) dω`.
    fn cap_quadrature(center: DVec3, radius: f64, x: DVec3, n: DVec3, k: usize) -> f64 {
        let q = center - x;
        let d = q.length();
        let w = q / d;
        let cos_a = (1.0 - (radius / d).powi(2)).sqrt();
        let (e1, e2) = w.any_orthonormal_pair();
        let mut sum = 0.0;
        for i in 0..k {
            let mu = 1.0 - (1.0 - cos_a) * (i as f64 + 0.5) / k as f64;
            let s = (1.0 - mu * mu).sqrt();
            for j in 0..k {
                let phi = 2.0 * PI * (j as f64 + 0.5) / k as f64;
                let om = mu * w + s * (phi.cos() * e1 + phi.sin() * e2);
                sum += n.dot(om).max(0.0);
            }
        }
        sum * 2.0 * PI * (1.0 - cos_a) / (k * k) as f64
    }

    /// E with the φ integral in closed form (∫ max(0, A + B cos ψ) dψ) and a
    /// fine midpoint rule over cos θ: a sharper check than `cap_quadrature`.
    fn ring_quadrature(sin2: f64, cos_b: f64, k: usize) -> f64 {
        let cos_a = (1.0 - sin2).sqrt();
        let sin_b = (1.0 - cos_b * cos_b).sqrt();
        let mut sum = 0.0;
        for i in 0..k {
            let mu = 1.0 - (1.0 - cos_a) * (i as f64 + 0.5) / k as f64;
            let (a, b) = (mu * cos_b, (1.0 - mu * mu).sqrt() * sin_b);
            sum += if a >= b {
                2.0 * PI * a
            } else if a <= -b {
                0.0
            } else {
                2.0 * (a * (-a / b).acos() + (b * b - a * a).sqrt())
            };
        }
        sum * (1.0 - cos_a) / k as f64
    }

    #[test]
    fn wholly_above_is_the_point_law() {
        let c = DVec3::new(0.3, 2.0, -1.0);
        let mut rng = Rng(1);
        for _ in 0..500 {
            let r = rng.range(0.01, 1.0);
            let d = r * rng.range(1.001, 50.0);
            let w = rng.unit();
            let x = c - d * w;
            let n = rng.unit();
            let (sin_a, cos_b) = (r / d, n.dot(w));
            let want = if cos_b >= sin_a {
                PI * sin_a * sin_a * cos_b
            } else if cos_b <= -sin_a {
                0.0
            } else {
                continue;
            };
            let got = irradiance(c, r, x, n);
            assert!(
                (got - want).abs() <= 1e-14 * want.max(1e-300),
                "{got} vs {want}"
            );
        }
    }

    #[test]
    fn the_horizon_case_matches_snyder_and_quadrature() {
        let mut rng = Rng(2);
        let c = DVec3::new(-1.0, 0.5, 2.0);
        let (mut vs_snyder, mut vs_ring, mut cases) = (0f64, 0f64, 0);
        while cases < 400 {
            let r = rng.range(0.05, 1.0);
            let d = r * rng.range(1.0005, 20.0);
            let sin_a = r / d;
            let w = rng.unit();
            // A normal within the band |cos β| < sin α.
            let cos_b = sin_a * rng.range(-1.0, 1.0);
            let (e1, _) = w.any_orthonormal_pair();
            let n = cos_b * w + (1.0 - cos_b * cos_b).sqrt() * e1;
            let got = irradiance(c, r, c - d * w, n);
            let sn = snyder(sin_a * sin_a, cos_b);
            let ring = ring_quadrature(sin_a * sin_a, cos_b, 20_000);
            let scale = PI * sin_a * sin_a;
            vs_snyder = vs_snyder.max((got - sn).abs() / scale);
            vs_ring = vs_ring.max((got - ring).abs() / scale);
            cases += 1;
        }
        // Relative to the cap's largest irradiance π sin²α.
        eprintln!("sphere horizon: vs Snyder {vs_snyder:e}, vs ring quadrature {vs_ring:e}");
        assert!(vs_snyder < 1e-12, "{vs_snyder}");
        assert!(vs_ring < 1e-8, "{vs_ring}");
    }

    #[test]
    fn matches_a_brute_force_quadrature() {
        let c = DVec3::new(0.0, 3.0, 0.0);
        let mut rng = Rng(4);
        let mut worst = 0f64;
        for i in 0..12 {
            let r = rng.range(0.3, 1.0);
            let d = r * rng.range(1.05, 4.0);
            let w = rng.unit();
            let sin_a = r / d;
            // Mostly horizon-cutting normals, some wholly above.
            let cos_b = if i % 3 == 0 {
                rng.range(sin_a, 1.0)
            } else {
                sin_a * rng.range(-0.9, 1.0)
            };
            let (e1, _) = w.any_orthonormal_pair();
            let n = cos_b * w + (1.0 - cos_b * cos_b).sqrt() * e1;
            let x = c - d * w;
            let got = irradiance(c, r, x, n);
            let want = cap_quadrature(c, r, x, n, 1500);
            worst = worst.max((got - want).abs() / (PI * sin_a * sin_a));
        }
        eprintln!("sphere cap quadrature: {worst:e}");
        assert!(worst < 1e-7, "{worst}");
    }

    #[test]
    fn continuous_across_the_horizon_and_stable_when_small() {
        for sin_a in [0.9, 0.5, 0.1, 1e-3, 1e-6] {
            let (r, d) = (sin_a, 1.0);
            let c = DVec3::new(0.0, 0.0, d);
            let e = |cos_b: f64| {
                let n = DVec3::new((1.0 - cos_b * cos_b).sqrt(), 0.0, cos_b);
                irradiance(c, r, DVec3::ZERO, n)
            };
            let top = PI * sin_a * sin_a;
            for edge in [sin_a, -sin_a] {
                for eps in [1e-12, 1e-9] {
                    let (a, b) = (e(edge * (1.0 - eps)), e(edge * (1.0 + eps)));
                    assert!((a - b).abs() <= 1e-8 * top, "{sin_a} {edge}: {a} vs {b}");
                }
            }
            // Along the band, against the ring quadrature, however small
            // the sphere.
            for k in 0..=20 {
                let cos_b = sin_a * (-1.0 + 2.0 * k as f64 / 20.0);
                let ring = ring_quadrature(sin_a * sin_a, cos_b, 20_000);
                let got = e(cos_b);
                assert!(
                    (got - ring).abs() <= 1e-7 * top,
                    "{sin_a} {cos_b}: {got} vs {ring}"
                );
                assert!(got >= 0.0 && got.is_finite());
            }
        }
        // atan z − z by its series and directly agree where they meet.
        for z in [0.249_999, 0.25, -0.2499, 1e-3, 1e-9] {
            let (s, d) = (atan_minus_identity(z), z.atan() - z);
            assert!(
                (s - d).abs() <= 1e-14 * z.abs().powi(3) + 1e-17,
                "{z}: {s} vs {d}"
            );
        }
    }

    #[test]
    fn small_spheres_keep_their_digits() {
        // (sin α, cos β, E) with E from Snyder's form in 60-digit arithmetic
        // (mpmath); in f64 that form erred 6e-11 at sin α = 1e-3 and 5e-7 at
        // 1e-5.
        let cases: [(f64, f64, f64); 5] = [
            (1e-3, 3e-4, 1.227_224_495_888_399e-9),
            (1e-5, 3e-6, 1.227_224_337_912_693e-15),
            (1e-5, -7e-6, 3.595_937_844_387_106e-17),
            (1e-7, 9e-8, 2.829_792_791_992_487e-21),
            (0.5, -0.1, 0.055_646_204_379_652_09),
        ];
        for (sin_a, cos_b, want) in cases {
            let n = DVec3::new((1.0 - cos_b * cos_b).sqrt(), 0.0, cos_b);
            let got = irradiance(DVec3::Z, sin_a, DVec3::ZERO, n);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{sin_a} {cos_b}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn inside_or_degenerate_points_get_zero_not_nan() {
        let c = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(irradiance(c, 1.0, c, DVec3::Z), 0.0);
        assert_eq!(irradiance(c, 1.0, c + DVec3::X, -DVec3::X), 0.0);
        assert_eq!(irradiance(c, 1.0, c + 0.5 * DVec3::Y, DVec3::Y), 0.0);
        assert_eq!(irradiance(c, 0.0, c + DVec3::X, -DVec3::X), 0.0);
        assert_eq!(cap_solid_angle(c, 1.0, c + 0.2 * DVec3::Z), 0.0);
        assert_eq!(cap_direction(c, 1.0, c + DVec3::Z, 0.5, 0.5), None);
        assert_eq!(cap_hit(c, 1.0, c, DVec3::Z), 0.0);
        // Just outside: the half-space limit, π/2 at grazing normals.
        let x = c + (1.0 + 1e-15) * DVec3::X;
        for n in [-DVec3::X, DVec3::Y, (DVec3::Y - DVec3::X).normalize()] {
            let e = irradiance(c, 1.0, x, n);
            assert!(e.is_finite() && (0.0..=PI).contains(&e), "{n}: {e}");
        }
        // A tiny far sphere: the point law, no underflow to NaN.
        let e = irradiance(DVec3::ZERO, 1e-150, DVec3::new(0.0, 0.0, -1e10), DVec3::Z);
        assert!(e.is_finite() && e >= 0.0, "{e}");
    }

    #[test]
    fn cap_directions_fill_the_cone_and_weigh_to_the_irradiance() {
        let c = DVec3::new(0.5, -0.2, 4.0);
        let mut rng = Rng(6);
        for _ in 0..20 {
            let r = rng.range(0.1, 1.0);
            let d = r * rng.range(1.01, 30.0);
            let w = rng.unit();
            let x = c - d * w;
            let sin_a = r / d;
            let cos_a = (1.0 - sin_a * sin_a).sqrt();
            // A normal with the cap wholly above its horizon.
            let cos_b = rng.range(sin_a, 1.0);
            let (e1, _) = w.any_orthonormal_pair();
            let n = cos_b * w + (1.0 - cos_b * cos_b).sqrt() * e1;
            let omega = cap_solid_angle(c, r, x);
            assert!((omega - 2.0 * PI * (1.0 - cos_a)).abs() < 1e-12 * omega);
            let k = 64;
            let mut mean = 0.0;
            for i in 0..k {
                for j in 0..k {
                    let (u1, u2) = ((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64);
                    let dir = cap_direction(c, r, x, u1, u2).unwrap();
                    assert!((dir.length() - 1.0).abs() < 1e-14);
                    assert!(dir.dot(w) >= cos_a - 1e-14, "{} {cos_a}", dir.dot(w));
                    // The hit is on the sphere, the nearer root, finite.
                    let t = cap_hit(c, r, x, dir);
                    assert!(t.is_finite() && t > 0.0);
                    let miss = ((x + t * dir - c).length() - r).abs();
                    assert!(miss < 1e-12 * d, "{miss}");
                    assert!(t <= dir.dot(c - x) + 1e-12 * d);
                    mean += n.dot(dir);
                }
            }
            mean /= (k * k) as f64;
            let e = irradiance(c, r, x, n);
            assert!(
                (omega * mean - e).abs() < 1e-12 * e,
                "{} vs {e}",
                omega * mean
            );
            // The cone's edge (u1 = 1) grazes: the tangent distance.
            let edge = cap_direction(c, r, x, 1.0, 0.3).unwrap();
            let t = cap_hit(c, r, x, edge);
            let tangent = (d * d - r * r).sqrt();
            assert!((t - tangent).abs() < 1e-6 * tangent, "{t} vs {tangent}");
        }
        // Away from the sphere: no hit.
        assert_eq!(
            cap_hit(c, 1.0, c - 3.0 * DVec3::Z, -DVec3::Z),
            f64::INFINITY
        );
    }
}
