//! The light space the kernels compute in, for either kind of light: a
//! rectangle's perspective space (light.rs) or a directional light's
//! orthographic one mapped onto it (sun.rs). The pipelines and both
//! backends move geometry with this, never with a light directly.

use crate::error::{Error, Result};
use crate::geom::light::AreaLight;
use crate::geom::light_shape::LightShape;
use crate::geom::sphere_light::SphereLight;
use crate::geom::sun::{DirectionalLight, SunSpace};
use glam::DVec3;

/// A light a user passes: a planar area light (a rectangle or a disk), the
/// sun, or a sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    Area(AreaLight),
    Sun(DirectionalLight),
    Sphere(SphereLight),
}

impl From<AreaLight> for Light {
    fn from(l: AreaLight) -> Light {
        Light::Area(l)
    }
}

impl From<DirectionalLight> for Light {
    fn from(l: DirectionalLight) -> Light {
        Light::Sun(l)
    }
}

impl Light {
    /// The light's shape in its kernel space (a point: a hard light).
    pub fn kernel_shape(&self) -> LightShape {
        match self {
            Light::Area(l) => l.shape(),
            Light::Sun(s) => s.kernel_shape(),
            // Not a kernel's shape (no light space, sphere_light.rs): its
            // silhouette seen from afar, for checks that ask for a size.
            Light::Sphere(s) => LightShape::disk(s.radius),
        }
    }

    /// What the light is called in messages.
    pub fn name(&self) -> &'static str {
        match self {
            Light::Area(l) => match l.shape {
                LightShape::Rect { .. } => "RectLight",
                LightShape::Disk { .. } => "DiskLight",
            },
            Light::Sun(_) => "DirectionalLight",
            Light::Sphere(_) => "SphereLight",
        }
    }

    /// Whether it casts hard shadows (a point light, a sun of size 0).
    pub fn is_hard(&self) -> bool {
        self.kernel_shape().is_point()
    }

    /// Its light space for a scene made of `points` (the sun's depth origin
    /// and range come from the scene; a rectangle's space is its own).
    pub fn space_for(&self, points: impl Iterator<Item = DVec3> + Clone) -> Result<LightSpace> {
        Ok(match self {
            Light::Area(l) => LightSpace::Area(*l),
            Light::Sun(s) => LightSpace::Sun(SunSpace::fit(*s, points)?),
            Light::Sphere(_) => return Err(sphere_has_no_space()),
        })
    }
}

/// The refusal of a light space for a sphere: the map methods project onto
/// a light's plane, which a sphere has not (sphere_light.rs).
pub fn sphere_has_no_space() -> Error {
    Error::invalid(
        "light",
        "a SphereLight has no plane to make light-view maps in: its shadows are traced \
         (softshadow.render with method \"exact\" or \"auto\")",
    )
}

/// The kernels' light space: perspective, relative to the light's centre,
/// the light its `shape` at depth 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightSpace {
    Area(AreaLight),
    Sun(SunSpace),
}

impl From<AreaLight> for LightSpace {
    fn from(l: AreaLight) -> LightSpace {
        LightSpace::Area(l)
    }
}

impl LightSpace {
    /// World point -> kernel light space (X, Y, Z): tangent X/Z, depth Z.
    #[inline]
    pub fn to_light(&self, p: DVec3) -> DVec3 {
        match self {
            LightSpace::Area(l) => l.to_light(p),
            LightSpace::Sun(s) => s.to_kernel(p),
        }
    }

    /// The world point at kernel depth `z` along tangent (x, y).
    #[inline]
    pub fn point_at(&self, x: f64, y: f64, z: f64) -> DVec3 {
        match self {
            LightSpace::Area(l) => l.point_at(x, y, z),
            LightSpace::Sun(s) => s.kernel_to_world(x, y, z),
        }
    }

    /// The light's shape in kernel units.
    pub fn shape(&self) -> LightShape {
        match self {
            LightSpace::Area(l) => l.shape(),
            LightSpace::Sun(s) => s.light.kernel_shape(),
        }
    }

    /// A kernel depth as the user's maps hold it: planar depth from the
    /// light's plane, or from the sun's depth origin.
    #[inline]
    pub fn user_depth(&self, z: f32) -> f32 {
        match self {
            LightSpace::Area(_) => z,
            LightSpace::Sun(s) => s.ortho_depth(z as f64) as f32,
        }
    }

    /// A depth of the user's maps -> the kernels'.
    #[inline]
    pub fn kernel_depth(&self, z: f32) -> f32 {
        match self {
            LightSpace::Area(_) => z,
            LightSpace::Sun(s) => s.kernel_depth(z as f64) as f32,
        }
    }

    /// Kernel tangent extents -> the user's: tangents, or world half-extents
    /// of an orthographic map.
    pub fn user_extent(&self, e: [f64; 2]) -> [f64; 2] {
        match self {
            LightSpace::Area(_) => e,
            LightSpace::Sun(s) => e.map(|t| t * s.lateral_scale()),
        }
    }

    /// The user's extents -> kernel tangent extents.
    pub fn kernel_extent(&self, e: [f64; 2]) -> [f64; 2] {
        match self {
            LightSpace::Area(_) => e,
            LightSpace::Sun(s) => e.map(|t| t / s.lateral_scale()),
        }
    }
}
