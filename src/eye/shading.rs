//! Direct lighting of Lambertian surfaces in the eye view: each pixel's
//! outgoing radiance toward the camera, without shadows (`unshadowed`) and
//! with the method's visibility (`shaded`).
//!
//! Maths. A Lambertian surface of albedo ρ at x with unit normal n reflects
//! `L_o = ρ/π · E` toward the camera, where E is the irradiance at x:
//!
//! * Area light of radiance L, emitting on its n_l side only: `E = L · F`,
//!   F its unoccluded form factor at x for normal n (`AreaLight::irradiance`;
//!   each shape's formula is in geom/light_shape/, for a rectangle
//!   Lambert's polygon formula after horizon clipping). E = 0 when x is at
//!   or behind the light's plane, and a point light (size 0) has no area.
//! * Sun of irradiance E_sun (on a surface facing it): `E = E_sun · max(0,
//!   n · s)`, `s = −n_l` the direction toward its centre. The angular size
//!   is ignored for the cosine: over a disc of angular radius a about s,
//!   wholly above the horizon, the mean of n · ω is `(n · s)(1 + cos a)/2`,
//!   a relative change of `(1 − cos a)/2 <= a²/4` (5.3e-6 for the real sun,
//!   a = 0.265°); a disc straddling the horizon changes E by at most
//!   `E_sun · sin a` absolute.
//!
//! Shadows multiply: `shaded = unshadowed · V`. The exact shaded
//! irradiance weights each visible part of the light by its cosine (and,
//! for a planar light, by 1/r² and the light's own cosine), `E = L ∫ V(ω)
//! cos θ dω`, so V is the *weighted* visibility where the method measured
//! one (an area light's under `exact`, whose rays weigh, `bitmask`, whose
//! light samples weigh, and `ssm`, whose micro-patches weigh:
//! methods/bitmask/weighted.rs, methods/ssm/weighted.rs), the ratio
//! estimator of Heitz, Hill & McGuire 2018; else the plain fraction of the
//! light seen, which agrees with it wherever V is 0 or 1 and differs in
//! penumbrae by how unevenly the light's parts are weighted (measured
//! against Mitsuba's `direct` integrator in docs/shading.md).
//!
//! Values are RGB. The checks of the user's emission and albedo live here
//! (`Lighting::new`); the bindings only convert Python numbers and
//! sequences into a `ColorValue`.

use super::GBuffer;
use crate::error::{Error, Result};
use crate::geom::light_space::Light;
use crate::geom::sun::DirectionalLight;
use glam::DVec3;
use rayon::prelude::*;

/// The albedo of every mesh when the call gives none (grey).
pub const DEFAULT_ALBEDO: f64 = 0.8;
/// A light's radiance (rectangle) or irradiance (sun) when none is given.
pub const DEFAULT_EMISSION: f64 = 1.0;

/// The largest emission, per channel: the largest f32. The images are f32
/// and no pixel exceeds its light's emission (`unshadowed` is albedo times
/// the emission times the form factor, at most 1, for a rectangle, and
/// times cos / π for the sun), so no finite input within it gives an
/// infinite pixel.
pub const MAX_EMISSION: f64 = f32::MAX as f64;

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
    if rgb.iter().all(|c| (0.0..=MAX_EMISSION).contains(c)) {
        Ok(rgb)
    } else {
        Err(Error::invalid(
            arg,
            format!("must be in [0, {MAX_EMISSION:e}] (finite in the float32 images), got {rgb:?}"),
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
        Light::Area(_) | Light::Sphere(_) => "radiance",
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

/// Irradiance on normal `n` (unit) from a sun of unit irradiance: the
/// cosine toward its centre (module doc).
pub fn sun_irradiance(s: &DirectionalLight, n: DVec3) -> f64 {
    (-s.n).dot(n).max(0.0)
}

/// Irradiance per unit emission at `x` with unit normal `n`, no shadows.
pub fn irradiance(light: &Light, x: DVec3, n: DVec3) -> f64 {
    match light {
        Light::Area(l) => l.irradiance(x, n),
        Light::Sun(s) => sun_irradiance(s, n),
        Light::Sphere(s) => s.irradiance(x, n),
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
    /// The albedo each pixel was shaded with.
    pub albedo: Vec<[f32; 3]>,
}

/// Shades every pixel of `g` that sees a surface (the G-buffer's position
/// and camera-facing geometric normal) under `light` of `emission`, with
/// its albedo `albedo` (albedo.rs) and its visibility `visibility`: the
/// weighted one where the method measured it (an area light's; module
/// doc), else the plain one.
pub fn shade(
    light: &Light,
    emission: [f64; 3],
    albedo: &[[f32; 3]],
    g: &GBuffer,
    visibility: &[f32],
    weighted: Option<&[f32]>,
) -> Shaded {
    let visibility = match (light, weighted) {
        (Light::Area(_) | Light::Sphere(_), Some(w)) => w,
        _ => visibility,
    };
    /// Pixels per parallel task: a few rows of a 640-wide image.
    const CHUNK: usize = 2048;
    let n = g.len();
    // Written in place, chunk by chunk: collecting a pair of outputs per
    // pixel (`unzip`) went through rayon's linked lists of vectors.
    let mut out = Shaded {
        shaded: vec![[0.0; 3]; n],
        unshadowed: vec![[0.0; 3]; n],
        albedo: albedo.to_vec(),
    };
    out.unshadowed
        .par_chunks_mut(CHUNK)
        .zip(out.shaded.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(chunk, (unshadowed, shaded))| {
            let start = chunk * CHUNK;
            for (i, (u, s)) in unshadowed.iter_mut().zip(shaded).enumerate() {
                let k = start + i;
                if g.mesh_id[k] < 0 {
                    continue;
                }
                let x = DVec3::from_array(g.position[k]);
                let normal = DVec3::from_array(g.normal[k].map(f64::from)).normalize_or_zero();
                let e = irradiance(light, x, normal) / std::f64::consts::PI;
                let v = f64::from(visibility[k]);
                let rho = albedo[k];
                for c in 0..3 {
                    let o = f64::from(rho[c]) * emission[c] * e;
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

    #[test]
    fn values_are_checked() {
        let num = ColorValue::Number;
        let list = ColorValue::List;
        assert_eq!(emission("radiance", None).unwrap(), [1.0; 3]);
        assert!(emission("radiance", Some(&num(-1.0))).is_err());
        assert!(emission("radiance", Some(&num(f64::NAN))).is_err());
        assert!(emission("radiance", Some(&num(1e300))).is_err());
        assert!(emission("radiance", Some(&num(MAX_EMISSION))).is_ok());
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
