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
//! The plane's side of a light point (x, y) in kernel units is
//! `s(x, y) = a0 + a1 x + a2 y` (the `RayStart::side` coefficients,
//! rays.rs); the fraction of the light with s >= 0 is the light shape's own
//! closed form (`LightShape::front_fraction`; the rectangle's in
//! geom/light_shape/rect.rs).

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
    plane_side(space, unit, p, n).map_or(0.0, |s| light.front_fraction(s))
}
