//! The light's shape in its own plane: the one type every stage asks about
//! the light, so that a new shape (a disk, a sphere's silhouette) is this
//! file plus the kernels' sampling and clipping.
//!
//! The light lies in the plane Z = 0 of light space (light.rs), centred on
//! the origin; its points are (x, y, 0) in the same units as depths (the
//! user's, or the depth unit's once `in_unit` has scaled it).
//!
//! * **Rect** `{ size: [sx, sy] }`: the rectangle [-sx/2, sx/2] x
//!   [-sy/2, sy/2]. `size = [0, 0]` is a point light (hard shadows,
//!   methods/point_light.rs); otherwise both sides are finite and > 0.
//! * **Bounds.** Every point of the light lies within the half-extents
//!   (hx, hy) = (sx/2, sy/2). An occluder point at tangent t and depth z
//!   shadows a receiver at depth z_r only within t ± h (1/z - 1/z_r) (the
//!   light seen through it, scaled onto the receiver's tangent plane): the
//!   reach that framing (extent.rs, eye focus), the gather kernels' windows
//!   and chunks, PCSS's search box and the smoothies' width all bound.
//! * **Sampling** (exact, the eye view's rays): a x b strata, a x b =
//!   samples, the longer side taking the larger count (`sample_grid`); the
//!   jittered sample (ja, jb) in [0, 1)^2 of stratum (sa, sb) is the point
//!   (((sa + ja)/a - 1/2) sx, ((sb + jb)/b - 1/2) sy) (`LightSamples`).
//! * **Clipping** (the map kernels: ssm's overlap, gather/hierarchy.rs,
//!   the bitmask's ranks): light coordinates in half-light units
//!   s = x / (sx/2), t = y / (sy/2), where the light is [-1, 1]^2 and a
//!   micro-patch's coverage is the product of two interval overlaps
//!   (`HalfLight`).
//!
//! * **Irradiance** (the eye view's shading, eye/shading.rs): the
//!   unoccluded irradiance E at a world point x with unit normal n from
//!   the light of unit radiance placed in the world (`Placement`: centre c
//!   and light.rs's frame u, v, n_l), emitting on its n_l side only
//!   (`LightShape::irradiance`). For the rectangle: the irradiance of a
//!   one-sided Lambertian polygon (Lambert's polygon formula),
//!   `E = ½ Σ_i Θ_i (n · Γ_i)`, with p_i the polygon's corners relative
//!   to x, `Θ_i = ∠(p_i, p_{i+1})` the angle edge i subtends at x and
//!   `Γ_i = p_i × p_{i+1} / |p_i × p_{i+1}|` the unit normal of the plane
//!   through x and edge i. The corners go (−u,−v), (+u,−v), (+u,+v), (−u,+v);
//!   since u × v = −n_l (light.rs's frame is left-handed), that order is
//!   counter-clockwise seen from the lit side and makes the sum positive.
//!   The formula integrates cos θ over the polygon's solid angle, which only
//!   counts where cos θ > 0: the polygon is first clipped to the upper
//!   hemisphere of x, the half-space `n · p >= 0` (Sutherland–Hodgman
//!   against the tangent plane, "horizon clipping"; a convex quad stays
//!   convex, at most five corners). E = 0 when x is at or behind the
//!   light's plane, `(x − c) · n_l <= 0` (the light emits on one side), and
//!   a point light (size 0) has no area, so E = 0.
//! * **Sides of a plane** (the eye view's casting triangles,
//!   eye/casters.rs): whether the whole light lies strictly on one side of
//!   a plane (`LightShape::strict_side`; the rectangle: its four corners).
//!
//! Each quantity is computed here in the order the kernels always did (in
//! f64, rounded once to f32), so moving it here changed no bit.

use crate::error::{Error, Result};
use crate::geom::units::{MAX_RELATIVE_SIZE, MIN_RELATIVE_SIZE};
use glam::DVec3;

/// The shape of a light in its plane (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightShape {
    /// Full width along u and full height along v; [0, 0]: a point light.
    Rect { size: [f64; 2] },
}

impl LightShape {
    /// A point light: the rectangle of size 0.
    pub const POINT: LightShape = LightShape::Rect { size: [0.0, 0.0] };

    /// The rectangle of full width and height `size`, unchecked (`check`).
    pub const fn rect(size: [f64; 2]) -> LightShape {
        LightShape::Rect { size }
    }

    /// The shape, or an error naming `arg`: a rectangle's sides both finite
    /// and > 0, or both 0 (a point light).
    pub fn check(self, arg: &str) -> Result<LightShape> {
        let LightShape::Rect { size } = self;
        if size.iter().all(|s| s.is_finite() && *s > 0.0) || size == [0.0, 0.0] {
            Ok(self)
        } else {
            Err(Error::invalid(
                arg,
                format!(
                    "must be two finite sizes > 0 (full width, full height), or (0, 0) for a \
                     point light, got {size:?}"
                ),
            ))
        }
    }

    /// Whether a (checked) shape is a point light's.
    pub fn is_point(&self) -> bool {
        let LightShape::Rect { size } = self;
        *size == [0.0, 0.0]
    }

    /// The shape with every length divided by `unit` (a power of two:
    /// exact, units.rs), refused when the kernels cannot resolve it: a
    /// ratio to the receivers' depth outside [MIN_RELATIVE_SIZE,
    /// MAX_RELATIVE_SIZE] makes 2/L or L/2 leave the f32 range.
    pub fn in_unit(&self, arg: &str, unit: f64) -> Result<LightShape> {
        let LightShape::Rect { size } = *self;
        let s = [size[0] / unit, size[1] / unit];
        if self.is_point() {
            return Ok(LightShape::POINT);
        }
        if s.iter()
            .all(|x| (MIN_RELATIVE_SIZE..=MAX_RELATIVE_SIZE).contains(x))
        {
            return Ok(LightShape::rect(s));
        }
        Err(Error::invalid(
            arg,
            format!(
                "{size:?} is {:?} times the receivers' depth ({unit:e}); the kernels compute in \
                 f32 and resolve ratios in [{MIN_RELATIVE_SIZE:e}, {MAX_RELATIVE_SIZE:e}] (a \
                 smaller light casts the hard shadow: pass (0, 0) for a point light)",
                s
            ),
        ))
    }

    /// The full width and height (2 hx, 2 hy) of the light's bounding box.
    pub fn extent(&self) -> [f64; 2] {
        let LightShape::Rect { size } = *self;
        size
    }

    /// The half-extents (hx, hy) = (sx/2, sy/2): every light point has
    /// |x| <= hx, |y| <= hy; the penumbra reach is h (1/z - 1/z_r).
    pub fn half_extent(&self) -> [f64; 2] {
        let LightShape::Rect { size } = *self;
        [0.5 * size[0], 0.5 * size[1]]
    }

    /// The larger full side of the bounding box, max(2 hx, 2 hy): the
    /// widest penumbra is this times (1/z_near - 1/z_r,far).
    pub fn largest_width(&self) -> f64 {
        let [sx, sy] = self.extent();
        sx.max(sy)
    }

    /// The stratification a x b = samples, a the largest divisor <= sqrt,
    /// the longer side of the light getting the larger count.
    pub fn sample_grid(&self, samples: u32) -> (u32, u32) {
        let LightShape::Rect { size } = *self;
        let mut a = (samples as f64).sqrt() as u32;
        while a > 1 && !samples.is_multiple_of(a) {
            a -= 1;
        }
        let a = a.max(1);
        let b = samples / a;
        if size[0] >= size[1] {
            (b, a)
        } else {
            (a, b)
        }
    }

    /// The fewest samples, at least `n`, whose stratification is near
    /// square: a x b with a = ceil(sqrt n), b = ceil(n / a) (so a - 1 <= b
    /// <= a and `sample_grid` gives that grid). A count a planner derives
    /// from an error law is arbitrary, and a prime one is stratified along
    /// one axis only (n x 1): `exact` with 167 samples erred 0.0154 (the
    /// estimate's upper end) on bunny_on_slab at 320x240 where 144 (12 x
    /// 12) erred 0.0055.
    pub fn square_count(n: u32) -> u32 {
        let a = (n.max(1) as f64).sqrt().ceil() as u32;
        a * n.max(1).div_ceil(a)
    }

    /// The f32 sample pattern of `samples` rays per receiver.
    pub fn samples(&self, samples: u32) -> LightSamples {
        let LightShape::Rect { size } = *self;
        LightSamples {
            grid: self.sample_grid(samples),
            size: size.map(|s| s as f32),
        }
    }

    /// The map kernels' half-light units, in f32.
    pub fn half_light(&self) -> HalfLight {
        let LightShape::Rect { size } = *self;
        HalfLight {
            inv_half: [(2.0 / size[0]) as f32, (2.0 / size[1]) as f32],
            half: [(0.5 * size[0]) as f32, (0.5 * size[1]) as f32],
        }
    }

    /// An f32 tangent x in half-light units, scaled in f64 and rounded once
    /// (`x * 2 / sx`; the kernels' column edges, CPU and GPU alike).
    pub fn x_in_half_light(&self, x: f32) -> f32 {
        let LightShape::Rect { size } = *self;
        (x as f64 * 2.0 / size[0]) as f32
    }

    /// The unoccluded irradiance at `x` (unit normal `n`) from this shape of
    /// unit radiance placed at `at`: its form factor (module doc; the
    /// rectangle's is Lambert's polygon formula after horizon clipping).
    pub fn irradiance(&self, at: &Placement, x: DVec3, n: DVec3) -> f64 {
        let LightShape::Rect { size } = *self;
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

    /// The plane's normal `n` turned toward this shape placed at `at` when
    /// the whole light lies strictly on one side of the plane (through
    /// `p0`), farther than `tol`; None when the light meets the plane.
    pub fn strict_side(&self, at: &Placement, p0: DVec3, n: DVec3, tol: f64) -> Option<DVec3> {
        let LightShape::Rect { size } = *self;
        let d = rect_corners(size, at).map(|c| n.dot(c - p0));
        if d.iter().all(|&x| x > tol) {
            Some(n)
        } else if d.iter().all(|&x| x < -tol) {
            Some(-n)
        } else {
            None
        }
    }
}

/// Where a light's shape lies in the world: its centre and light.rs's
/// frame (u, v along its plane, n from the light into the scene).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub center: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub n: DVec3,
}

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

/// Where the rays of a receiver go on the light, in f32 (the ray casters'
/// inner loops; `gpu/light_shape.wgsl` is the device's twin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSamples {
    /// The strata a x b (`LightShape::sample_grid`).
    pub grid: (u32, u32),
    /// The rectangle's full width and height.
    pub size: [f32; 2],
}

impl LightSamples {
    /// The light point of stratum (sa, sb) jittered by (ja, jb) in [0, 1)^2:
    /// (((sa + ja)/a - 1/2) sx, ((sb + jb)/b - 1/2) sy).
    #[inline(always)]
    pub fn point(&self, sa: u32, sb: u32, ja: f32, jb: f32) -> (f32, f32) {
        let (na, nb) = self.grid;
        let x = ((sa as f32 + ja) / na as f32 - 0.5) * self.size[0];
        let y = ((sb as f32 + jb) / nb as f32 - 0.5) * self.size[1];
        (x, y)
    }

    /// The box [[x0, x1], [y0, y1]] holding every sample of strata
    /// [a0, a1) x [b0, b1) (the shaft culling's target).
    pub fn region(&self, a0: u32, a1: u32, b0: u32, b1: u32) -> [[f32; 2]; 2] {
        let (na, nb) = self.grid;
        let x = |a: u32| (a as f32 / na as f32 - 0.5) * self.size[0];
        let y = |b: u32| (b as f32 / nb as f32 - 0.5) * self.size[1];
        [[x(a0), x(a1)], [y(b0), y(b1)]]
    }
}

/// The map kernels' clipping scales: light coordinates (x, y) become
/// `(x * inv_half[0], y * inv_half[1])`, in which the light is `[-1, 1]^2`;
/// `half` turns 1/depth differences back into tangent reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfLight {
    /// (2/sx, 2/sy), rounded once from f64.
    pub inv_half: [f32; 2],
    /// (sx/2, sy/2), rounded once from f64.
    pub half: [f32; 2],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::RectLight;

    /// Irradiance of a unit-radiance rectangle by a midpoint quadrature over
    /// its area, `∫ cos θ_x max(0, cos θ_l) / r² dA` with θ_x clamped at the
    /// horizon.
    fn quadrature(l: &RectLight, x: DVec3, n: DVec3, k: usize) -> f64 {
        let area = l.size[0] * l.size[1];
        let mut sum = 0.0;
        for i in 0..k {
            for j in 0..k {
                let s = ((i as f64 + 0.5) / k as f64 - 0.5) * l.size[0];
                let t = ((j as f64 + 0.5) / k as f64 - 0.5) * l.size[1];
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

    fn light() -> RectLight {
        RectLight::new(
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
            let p = l.corners().map(|c| c - x);
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
            RectLight::new([0.0; 3], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0]).unwrap();
        assert_eq!(point.irradiance(DVec3::new(0.0, -1.0, 0.0), DVec3::Y), 0.0);
    }

    #[test]
    fn shapes_are_checked_and_scaled() {
        assert!(LightShape::rect([0.0, 1.0]).check("size").is_err());
        assert!(LightShape::rect([-0.0, 0.0]).check("size").is_ok());
        assert!(LightShape::rect([1.0, f64::NAN]).check("size").is_err());
        assert!(LightShape::rect([-0.0, 0.0]).is_point());
        let one = LightShape::rect([1.0, 1.0]);
        assert!(one.in_unit("size", 2f64.powi(51)).is_ok());
        assert!(LightShape::rect([1e-40, 1.0]).in_unit("size", 1.0).is_err());
        assert!(LightShape::rect([1e-40, 1e-40])
            .in_unit("size", 2f64.powi(-100))
            .is_ok());
        assert_eq!(
            LightShape::POINT.in_unit("size", 4.0).unwrap(),
            LightShape::POINT
        );
    }

    #[test]
    fn sample_grids_are_near_square_and_samples_cover_the_light() {
        assert_eq!(LightShape::rect([1.0, 1.0]).sample_grid(256), (16, 16));
        assert_eq!(LightShape::rect([2.0, 1.0]).sample_grid(12), (4, 3));
        assert_eq!(LightShape::rect([1.0, 2.0]).sample_grid(12), (3, 4));
        assert_eq!(LightShape::rect([1.0, 1.0]).sample_grid(7), (7, 1));
        // Counts rounded up to a near-square grid.
        for n in 1..5000 {
            let m = LightShape::square_count(n);
            let (a, b) = LightShape::rect([1.0, 1.0]).sample_grid(m);
            assert!(m >= n && a.abs_diff(b) <= 1, "{n} -> {m} = {a} x {b}");
            assert!(m < n + 2 * (n as f64).sqrt() as u32 + 2, "{n} -> {m}");
        }
        assert_eq!(LightShape::square_count(167), 169);
        assert_eq!(LightShape::square_count(144), 144);
        assert_eq!(LightShape::square_count(16384), 16384);
        let s = LightShape::rect([2.0, 1.0]).samples(12);
        assert_eq!(s.point(0, 0, 0.0, 0.0), (-1.0, -0.5));
        assert_eq!(s.region(0, 4, 0, 3), [[-1.0, 1.0], [-0.5, 0.5]]);
        assert_eq!(LightShape::rect([2.0, 1.0]).half_extent(), [1.0, 0.5]);
        assert_eq!(
            LightShape::rect([2.0, 1.0]).half_light().inv_half,
            [1.0, 2.0]
        );
    }
}
