//! A spherical area light: a uniform Lambertian emitter of radius R centred
//! at c, bright on its whole surface.
//!
//! Seen from a point x outside it (d = |c − x| > R), the sphere is the cap
//! of directions within α of c − x, sin α = R / d: its visible surface is
//! the part facing x, and the light's other half is hidden by the sphere
//! itself. So a ray caster samples that cap (uniform in solid angle,
//! `light_shape::sphere::cap_direction`) and stops each ray at the
//! sphere's near surface (`cap_hit`), and the unshadowed irradiance is the
//! cap's form factor (`light_shape::sphere::irradiance`: π sin²α cos β
//! above the horizon, the horizon-clipped cap's closed form across it).
//!
//! A sphere has no plane to project a light-view map in: the map methods,
//! which back-project occluder texels onto the light's plane, refuse it
//! (the eye view's `exact` traces it).

use crate::error::{Error, Result};
use crate::geom::light::finite3;
use crate::geom::light_shape::sphere;
use glam::DVec3;

/// A sphere emitting uniformly over its whole surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereLight {
    pub center: DVec3,
    pub radius: f64,
}

impl SphereLight {
    /// The sphere at `center` of `radius` (finite, > 0), or an error naming
    /// the argument.
    pub fn new(center: [f64; 3], radius: f64) -> Result<SphereLight> {
        let center = finite3("center", center)?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::invalid(
                "radius",
                format!("must be a finite radius > 0, got {radius}"),
            ));
        }
        Ok(SphereLight { center, radius })
    }

    /// The unoccluded irradiance at `x` (unit normal `n`) from the sphere of
    /// unit radiance: its visible cap's form factor (0 inside the sphere).
    pub fn irradiance(&self, x: DVec3, n: DVec3) -> f64 {
        sphere::irradiance(self.center, self.radius, x, n)
    }

    /// Whether `x` lies strictly outside the sphere, where it sees a cap.
    pub fn is_outside(&self, x: DVec3) -> bool {
        (x - self.center).length() > self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spheres_are_checked() {
        assert!(SphereLight::new([0.0; 3], 1.0).is_ok());
        assert!(SphereLight::new([0.0; 3], 0.0).is_err());
        assert!(SphereLight::new([0.0; 3], -1.0).is_err());
        assert!(SphereLight::new([0.0; 3], f64::NAN).is_err());
        assert!(SphereLight::new([f64::NAN, 0.0, 0.0], 1.0).is_err());
        let s = SphereLight::new([0.0, 0.0, 3.0], 1.0).unwrap();
        assert!(s.is_outside(DVec3::ZERO) && !s.is_outside(DVec3::new(0.0, 0.0, 2.5)));
    }
}
