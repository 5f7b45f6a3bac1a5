//! Where a shadow ray leaves a surface point: one origin above the surface
//! and one below it, and the tangent plane that picks between them for a
//! light point (a ray toward the light's side of the surface starts on
//! that side; one through the surface starts behind it). Built by the eye
//! view (`eye::rays::ray_starts`, which says how far the origins are moved);
//! read by the engines and by the map methods' weighted visibility.

use super::shadow_rays::{Origins, RayOrigin, SurfacePoint};
use glam::Vec3;

/// A shadow ray's start for a surface point, in kernel light space: the
/// origins above and below the surface, and the side of the surface a light
/// point (x, y) lies on: `side[0] + x side[1] + y side[2] >= 0` is above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayStart {
    pub above: Vec3,
    pub below: Vec3,
    pub side: [f32; 3],
}

impl RayStart {
    /// The surface point it starts from (the midpoint of its starts) and
    /// its tangent plane.
    #[inline(always)]
    pub(crate) fn surface_point(&self) -> SurfacePoint {
        SurfacePoint {
            p: 0.5 * (self.above + self.below),
            side: self.side,
        }
    }

    /// The origin of the ray toward the light point (x, y).
    #[inline]
    pub fn origin(&self, x: f32, y: f32) -> Vec3 {
        if self.side[0] + x * self.side[1] + y * self.side[2] >= 0.0 {
            self.above
        } else {
            self.below
        }
    }
}

impl RayOrigin for RayStart {
    #[inline(always)]
    fn bounds(&self) -> (Vec3, Vec3) {
        (self.above.min(self.below), self.above.max(self.below))
    }
    #[inline(always)]
    fn origin(&self, x: f32, y: f32) -> Vec3 {
        RayStart::origin(self, x, y)
    }
    const WEIGHTED: bool = true;
    /// The light point (x, y, 0)'s share of the irradiance at the surface
    /// point (kernel space, the origins' midpoint): `SurfacePoint::weight`.
    #[inline(always)]
    fn weight(&self, x: f32, y: f32) -> f32 {
        self.surface_point().weight(x, y)
    }
    #[inline(always)]
    fn surface(&self) -> Option<SurfacePoint> {
        Some(self.surface_point())
    }
    #[inline(always)]
    fn origins(&self) -> Origins {
        Origins::Two {
            above: self.above,
            below: self.below,
            side: self.side,
        }
    }
}
