//! Direct lighting of Lambertian surfaces in the eye view: each pixel's
//! outgoing radiance toward the camera, without shadows (`unshadowed`) and
//! with the method's visibility (`shaded`).
//!
//! Maths. A Lambertian surface of albedo ρ at x with unit normal n reflects
//! `L_o = ρ/π · E` toward the camera, where E is the irradiance at x:
//!
//! * Rectangle of radiance L, emitting on its n_l side only: the irradiance
//!   of a one-sided Lambertian polygon (Lambert's polygon formula),
//!   `E = L · ½ Σ_i Θ_i (n · Γ_i)`, with p_i the polygon's corners relative
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
//! * Sun of irradiance E_sun (on a surface facing it): `E = E_sun · max(0,
//!   n · s)`, `s = −n_l` the direction toward its centre. The angular size
//!   is ignored for the cosine: over a disc of angular radius a about s,
//!   wholly above the horizon, the mean of n · ω is `(n · s)(1 + cos a)/2`,
//!   a relative change of `(1 − cos a)/2 <= a²/4` (5.3e-6 for the real sun,
//!   a = 0.265°); a disc straddling the horizon changes E by at most
//!   `E_sun · sin a` absolute.
//!
//! Shadows multiply: `shaded = unshadowed · V` with V the method's
//! visibility, the *unweighted* fraction of the light seen. That is an
//! approximation: the exact shaded irradiance weights each visible part of
//! the light by its cosine (and, for a rectangle, by 1/r² and the light's
//! own cosine), `E = L ∫ V(ω) cos θ dω`; the two agree wherever V is 0 or 1
//! and differ in penumbrae by how unevenly the light's parts are weighted
//! (measured against Mitsuba's `direct` integrator in docs/shading.md).
//!
//! Values are RGB. The checks of the user's emission and albedo live here
//! (`Lighting::new`); the bindings only convert Python numbers and
//! sequences into a `ColorValue`.

use super::GBuffer;
use crate::error::{Error, Result};
use crate::geom::light::RectLight;
use crate::geom::light_space::Light;
use crate::geom::sun::DirectionalLight;
use glam::DVec3;
use rayon::prelude::*;

/// The albedo of every mesh when the call gives none (grey).
pub const DEFAULT_ALBEDO: f64 = 0.8;
/// A light's radiance (rectangle) or irradiance (sun) when none is given.
pub const DEFAULT_EMISSION: f64 = 1.0;

/// A value as the user gave it: a number, or a sequence of values.
#[derive(Debug, Clone, PartialEq)]
pub enum ColorValue {
    Number(f64),
    List(Vec<ColorValue>),
}

impl ColorValue {
    fn number(&self) -> Option<f64> {
        match self {
            ColorValue::Number(x) => Some(*x),
            ColorValue::List(_) => None,
        }
    }

    /// Three numbers: an RGB triple.
    fn triple(&self) -> Option<[f64; 3]> {
        match self {
            ColorValue::List(items) if items.len() == 3 => {
                let mut rgb = [0.0; 3];
                for (c, item) in rgb.iter_mut().zip(items) {
                    *c = item.number()?;
                }
                Some(rgb)
            }
            _ => None,
        }
    }

    /// A number (grey) or an RGB triple, or an error naming `arg`.
    fn color(&self, arg: &str) -> Result<[f64; 3]> {
        match (self.number(), self.triple()) {
            (Some(g), _) => Ok([g; 3]),
            (_, Some(rgb)) => Ok(rgb),
            _ => Err(Error::invalid(
                arg,
                format!(
                    "must be a number or 3 numbers (R, G, B), got {}",
                    self.describe()
                ),
            )),
        }
    }

    fn describe(&self) -> String {
        match self {
            ColorValue::Number(x) => format!("{x}"),
            ColorValue::List(items) => format!("a sequence of {} values", items.len()),
        }
    }
}

/// The light's emission: a rectangle's radiance, or the sun's irradiance on
/// a surface facing it. `None` takes `DEFAULT_EMISSION`.
pub fn emission(arg: &str, value: Option<&ColorValue>) -> Result<[f64; 3]> {
    let rgb = match value {
        None => [DEFAULT_EMISSION; 3],
        Some(v) => v.color(arg)?,
    };
    if rgb.iter().all(|c| c.is_finite() && *c >= 0.0) {
        Ok(rgb)
    } else {
        Err(Error::invalid(
            arg,
            format!("must be finite and >= 0, got {rgb:?}"),
        ))
    }
}

/// The albedo of each of `meshes` meshes: a number or an RGB triple for
/// all, or a sequence with one number or triple per mesh (three numbers are
/// always one RGB triple, whatever the number of meshes). Every value in
/// [0, 1]. `None` takes `DEFAULT_ALBEDO`.
pub fn albedo(value: Option<&ColorValue>, meshes: usize) -> Result<Vec<[f64; 3]>> {
    let in_range = |arg: &str, rgb: [f64; 3]| {
        if rgb.iter().all(|c| (0.0..=1.0).contains(c)) {
            Ok(rgb)
        } else {
            Err(Error::invalid(
                arg,
                format!("must be in [0, 1], got {rgb:?}"),
            ))
        }
    };
    let all = |rgb: [f64; 3]| in_range("albedo", rgb).map(|rgb| vec![rgb; meshes]);
    match value {
        None => all([DEFAULT_ALBEDO; 3]),
        Some(ColorValue::Number(g)) => all([*g; 3]),
        Some(v @ ColorValue::List(items)) => match v.triple() {
            Some(rgb) => all(rgb),
            None if items.len() == meshes => items
                .iter()
                .enumerate()
                .map(|(k, item)| {
                    let arg = format!("albedo[{k}]");
                    in_range(&arg, item.color(&arg)?)
                })
                .collect(),
            None => Err(Error::invalid(
                "albedo",
                format!(
                    "must be a number, an RGB triple or one per mesh ({meshes} meshes), got {}",
                    v.describe()
                ),
            )),
        },
    }
}

/// What a light's emission is called: a rectangle's `radiance`, the sun's
/// `irradiance`.
pub fn emission_arg(light: &Light) -> &'static str {
    match light {
        Light::Rect(_) => "radiance",
        Light::Sun(_) => "irradiance",
    }
}

/// What the shading of an image needs besides the G-buffer and visibility.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// The rectangle's radiance, or the sun's irradiance, RGB.
    pub emission: [f64; 3],
    /// Per mesh of the scene (indexed by `mesh_id`), RGB in [0, 1].
    pub albedo: Vec<[f64; 3]>,
}

impl Lighting {
    /// Checks the user's emission (named `radiance` for a rectangle,
    /// `irradiance` for the sun) and albedo for a scene of `meshes` meshes.
    pub fn new(
        light: &Light,
        emission_value: Option<&ColorValue>,
        albedo_value: Option<&ColorValue>,
        meshes: usize,
    ) -> Result<Lighting> {
        let arg = emission_arg(light);
        Ok(Lighting {
            emission: emission(arg, emission_value)?,
            albedo: albedo(albedo_value, meshes)?,
        })
    }
}

/// Irradiance at `x` (normal `n`, unit) from a rectangle of unit radiance:
/// Lambert's polygon formula after horizon clipping (module doc).
pub fn rect_irradiance(l: &RectLight, x: DVec3, n: DVec3) -> f64 {
    if (x - l.center).dot(l.n) <= 0.0 || l.size[0] * l.size[1] == 0.0 {
        return 0.0;
    }
    let p = l.corners().map(|c| c - x);
    if p.iter().all(|&q| n.dot(q) >= 0.0) {
        // The whole light above the horizon (most pixels): no clipping.
        return unclipped_quad(&p, n);
    }
    clipped_quad(&p, n)
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

/// Irradiance on normal `n` (unit) from a sun of unit irradiance: the
/// cosine toward its centre (module doc).
pub fn sun_irradiance(s: &DirectionalLight, n: DVec3) -> f64 {
    (-s.n).dot(n).max(0.0)
}

/// Irradiance per unit emission at `x` with unit normal `n`, no shadows.
pub fn irradiance(light: &Light, x: DVec3, n: DVec3) -> f64 {
    match light {
        Light::Rect(l) => rect_irradiance(l, x, n),
        Light::Sun(s) => sun_irradiance(s, n),
    }
}

/// The unshadowed irradiance (RGB, `emission` included) at world points
/// with the given normals (any length, normalized here), or an error naming
/// `points` or `normals` for non-finite values, zero normals or counts that
/// differ.
pub fn irradiance_at(
    light: &Light,
    emission: [f64; 3],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
) -> Result<Vec<[f64; 3]>> {
    if points.len() != normals.len() {
        return Err(Error::shape(
            "normals",
            format!("{} normals for {} points", normals.len(), points.len()),
        ));
    }
    if let Some(k) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::invalid(
            "points",
            format!("must be finite, got {:?} at row {k}", points[k]),
        ));
    }
    let unit: Vec<DVec3> = normals
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let v = DVec3::from_array(*n);
            match v.try_normalize() {
                Some(u) if v.is_finite() => Ok(u),
                _ => Err(Error::invalid(
                    "normals",
                    format!("must be finite and non-zero, got {n:?} at row {k}"),
                )),
            }
        })
        .collect::<Result<_>>()?;
    Ok(points
        .par_iter()
        .zip(unit)
        .map(|(p, n)| {
            let e = irradiance(light, DVec3::from_array(*p), n);
            emission.map(|c| c * e)
        })
        .collect())
}

/// The shaded images (H, W) RGB, row-major; 0 where no surface.
#[derive(Debug, Clone, Default)]
pub struct Shaded {
    /// `unshadowed · V`.
    pub shaded: Vec<[f32; 3]>,
    /// `albedo/π · E`: the outgoing radiance without shadows.
    pub unshadowed: Vec<[f32; 3]>,
}

/// Shades every pixel of `g` that sees a surface (the G-buffer's position
/// and camera-facing geometric normal) with its visibility `visibility`.
pub fn shade(light: &Light, lighting: &Lighting, g: &GBuffer, visibility: &[f32]) -> Shaded {
    /// Pixels per parallel task: a few rows of a 640-wide image.
    const CHUNK: usize = 2048;
    let n = g.len();
    // Written in place, chunk by chunk: collecting a pair of outputs per
    // pixel (`unzip`) went through rayon's linked lists of vectors.
    let mut out = Shaded {
        shaded: vec![[0.0; 3]; n],
        unshadowed: vec![[0.0; 3]; n],
    };
    out.unshadowed
        .par_chunks_mut(CHUNK)
        .zip(out.shaded.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(chunk, (unshadowed, shaded))| {
            let start = chunk * CHUNK;
            for (i, (u, s)) in unshadowed.iter_mut().zip(shaded).enumerate() {
                let k = start + i;
                let Ok(mesh) = usize::try_from(g.mesh_id[k]) else {
                    continue;
                };
                let x = DVec3::from_array(g.position[k]);
                let normal = DVec3::from_array(g.normal[k].map(f64::from)).normalize_or_zero();
                let e = irradiance(light, x, normal) / std::f64::consts::PI;
                let v = f64::from(visibility[k]);
                let rho = lighting.albedo[mesh];
                for c in 0..3 {
                    let o = rho[c] * lighting.emission[c] * e;
                    u[c] = o as f32;
                    s[c] = (o * v) as f32;
                }
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
            let got = rect_irradiance(&l, x, n);
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
        assert_eq!(
            rect_irradiance(&l, DVec3::new(0.0, 2.5, 0.0), DVec3::Y),
            0.0
        );
        assert_eq!(
            rect_irradiance(&l, DVec3::new(0.0, 2.0, 0.0), -DVec3::Y),
            0.0
        );
        let point =
            RectLight::new([0.0; 3], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0]).unwrap();
        assert_eq!(
            rect_irradiance(&point, DVec3::new(0.0, -1.0, 0.0), DVec3::Y),
            0.0
        );
    }

    #[test]
    fn values_are_checked() {
        let num = ColorValue::Number;
        let list = ColorValue::List;
        assert_eq!(emission("radiance", None).unwrap(), [1.0; 3]);
        assert!(emission("radiance", Some(&num(-1.0))).is_err());
        assert!(emission("radiance", Some(&num(f64::NAN))).is_err());
        assert!(emission("radiance", Some(&list(vec![num(1.0), num(2.0)]))).is_err());
        assert_eq!(albedo(None, 2).unwrap(), vec![[0.8; 3]; 2]);
        let rgb = list(vec![num(0.1), num(0.2), num(0.3)]);
        assert_eq!(albedo(Some(&rgb), 2).unwrap(), vec![[0.1, 0.2, 0.3]; 2]);
        let two = list(vec![num(0.5), rgb.clone()]);
        assert_eq!(
            albedo(Some(&two), 2).unwrap(),
            vec![[0.5; 3], [0.1, 0.2, 0.3]]
        );
        assert!(albedo(Some(&two), 4).is_err());
        let err = albedo(Some(&list(vec![num(0.5), num(1.5)])), 2).unwrap_err();
        assert!(err.to_string().starts_with("albedo[1]:"), "{err}");
    }
}
