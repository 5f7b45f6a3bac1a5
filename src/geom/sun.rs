//! The directional light (the sun) and its orthographic light space: the one
//! place that owns their conventions.
//!
//! * Frame: `n = normalize(direction)` is the direction the light travels,
//!   `v = normalize(up - (up.n) n)`, `u = n x v` (as for `AreaLight`).
//! * The light is the set of travel directions `n + x u + y v` with
//!   `|x| <= tan(a_u/2)`, `|y| <= tan(a_v/2)`, uniform in (x, y): a rectangle
//!   at infinity. `angular_size = (a_u, a_v)` are full angles in degrees;
//!   `(0, 0)` is a hard directional light.
//! * Orthographic light space of a scene: `(X, Y, Z) = ((p-o).u, (p-o).v, (p-o).n)`
//!   with `o` the centre of the scene's bounding box moved along `n` onto the
//!   plane that touches the scene on the light's side: `Z >= 0` is the planar
//!   depth from that plane (the depth origin), X and Y are world units. An
//!   orthographic map of shape (H, W) with half-extents (ex, ey) (world
//!   units) has texel [j, i] centred at `X = (-1 + 2(i+1/2)/W) ex`,
//!   `Y = (1 - 2(j+1/2)/H) ey`, row 0 at the +v edge.
//!
//! The kernels work in a perspective light space (light.rs). The orthographic
//! one maps onto it exactly by a projective change of depth: with the scene's
//! depth range D, `S = max(D, tiny)` and `A = D + S`,
//!     x' = X / S,  y' = Y / S,  w' = 1/z' = (A - Z) / S   (in [1, 2] on the scene),
//! and a light of size `(2 tan(a_u/2), 2 tan(a_v/2))` at z' = 0. Then
//! `w'_O - w'_R = (Z_R - Z_O) / S`, so the perspective back-projection of a
//! micro-patch, `(x' - x'_R) / (w'_O - w'_R)`, is the orthographic one,
//! `(X - X_R) / (Z_R - Z_O)`, a tangent compared with the light's
//! `[-tan(a/2), tan(a/2)]`; lines map to lines (the map is projective), so a
//! segment to a light point at z' = 0 is the ray to infinity, triangles stay
//! triangles and rasterizing them gives the orthographic depth. Every kernel,
//! on both backends, runs unchanged; the maps go back to Z for the user.

use crate::error::{Error, Result};
use crate::geom::light::light_frame;
use crate::geom::light_shape::LightShape;
use glam::DVec3;

/// A directional light with its orthonormal frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    pub u: DVec3,
    pub v: DVec3,
    /// The direction the light travels.
    pub n: DVec3,
    /// Full angles in degrees along u and v.
    pub angular_size: [f64; 2],
}

/// The widest full angle accepted, in degrees: at 180 the tangent is infinite.
pub const MAX_ANGLE: f64 = 179.0;

impl DirectionalLight {
    pub fn new(direction: [f64; 3], up: [f64; 3], angular_size: [f64; 2]) -> Result<Self> {
        let (u, v, n) = light_frame("direction", direction, up)?;
        let ok = |a: f64| a.is_finite() && a > 0.0 && a <= MAX_ANGLE;
        if !(angular_size.iter().all(|&a| ok(a)) || angular_size == [0.0, 0.0]) {
            return Err(Error::invalid(
                "angular_size",
                format!(
                    "must be two full angles in degrees in (0, {MAX_ANGLE}], or (0, 0) for a hard \
                     directional light, got {angular_size:?}"
                ),
            ));
        }
        Ok(DirectionalLight {
            u,
            v,
            n,
            angular_size,
        })
    }

    /// Half-extents of the light in tangent units: (tan(a_u/2), tan(a_v/2)).
    pub fn half_tangents(&self) -> [f64; 2] {
        self.angular_size
            .map(|a| (0.5 * a).to_radians().tan().max(0.0))
    }

    /// The light's shape in the kernels' perspective space (see the module
    /// doc): the rectangle of full tangent sides 2 tan(a/2).
    pub fn kernel_shape(&self) -> LightShape {
        LightShape::rect(self.half_tangents().map(|t| 2.0 * t))
    }

    /// The unit direction toward the light's point (x, y) (tangent units).
    pub fn toward(&self, x: f64, y: f64) -> DVec3 {
        -(self.n + x * self.u + y * self.v).normalize()
    }
}

/// A directional light's orthographic space fitted to a scene, and its
/// projective map onto the kernels' perspective light space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunSpace {
    pub light: DirectionalLight,
    /// The depth origin: a world point on the plane Z = 0.
    pub origin: DVec3,
    /// The scene's depth range D (Z in [0, D]).
    pub depth_range: f64,
    /// S and A of the module doc.
    scale: f64,
    far: f64,
}

impl SunSpace {
    /// The space of a scene whose points are `points` (world).
    pub fn fit(
        light: DirectionalLight,
        points: impl Iterator<Item = DVec3> + Clone,
    ) -> Result<Self> {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(Error::invalid("scene", "has no vertices"));
        }
        let centre = 0.5 * (lo + hi);
        // Z over the box's corners bounds Z over the scene.
        let half = 0.5 * (hi - lo);
        let reach = half.x * light.n.x.abs() + half.y * light.n.y.abs() + half.z * light.n.z.abs();
        let origin = centre - reach * light.n;
        Ok(Self::new(light, origin, 2.0 * reach))
    }

    /// The space of a scene made of `points`, centred laterally on the
    /// points in `focus` (what a camera sees): the map is symmetric about
    /// the origin, so centring it on the visible part spends no texels on
    /// the rest (Scherzer et al. 2005, §4.1).
    pub fn fit_focused(
        light: DirectionalLight,
        points: impl Iterator<Item = DVec3>,
        focus: impl Iterator<Item = DVec3>,
    ) -> Result<Self> {
        let (mut z0, mut z1) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in points {
            let z = p.dot(light.n);
            z0 = z0.min(z);
            z1 = z1.max(z);
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in focus {
            let (x, y) = (p.dot(light.u), p.dot(light.v));
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        if !(z0.is_finite() && z1.is_finite() && lo[0].is_finite() && hi[0].is_finite()) {
            return Err(Error::invalid("scene", "has no vertices"));
        }
        let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
        let origin = cx * light.u + cy * light.v + z0 * light.n;
        Ok(Self::new(light, origin, z1 - z0))
    }

    /// The space with depth origin `origin` and depth range `depth_range`.
    pub fn new(light: DirectionalLight, origin: DVec3, depth_range: f64) -> Self {
        // A flat scene (D = 0) still needs a scale: the box's own size, or 1.
        let scale = if depth_range > 0.0 {
            depth_range
        } else {
            origin.abs().max_element().max(1.0) * 1e-6
        };
        SunSpace {
            light,
            origin,
            depth_range,
            scale,
            far: depth_range.max(0.0) + scale,
        }
    }

    /// World point -> orthographic (X, Y, Z).
    #[inline]
    pub fn to_ortho(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(
            d.dot(self.light.u),
            d.dot(self.light.v),
            d.dot(self.light.n),
        )
    }

    /// Orthographic (X, Y, Z) -> world point.
    #[inline]
    pub fn ortho_to_world(&self, q: DVec3) -> DVec3 {
        self.origin + q.x * self.light.u + q.y * self.light.v + q.z * self.light.n
    }

    /// World point -> the kernels' perspective light space (X', Y', Z').
    /// Points beyond Z = A (none in the fitted scene) have Z' <= 0: the
    /// kernels treat them as behind the light.
    #[inline]
    pub fn to_kernel(&self, p: DVec3) -> DVec3 {
        let q = self.to_ortho(p);
        let w = (self.far - q.z) / self.scale;
        let z = 1.0 / w;
        DVec3::new(q.x / self.scale * z, q.y / self.scale * z, z)
    }

    /// The kernels' (tangent x', y', depth z') -> world point.
    #[inline]
    pub fn kernel_to_world(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.ortho_to_world(DVec3::new(
            x * self.scale,
            y * self.scale,
            self.ortho_depth(z),
        ))
    }

    /// A kernel depth z' -> orthographic depth Z (inf stays inf: no surface).
    #[inline]
    pub fn ortho_depth(&self, z: f64) -> f64 {
        if z.is_finite() {
            self.far - self.scale / z
        } else {
            z
        }
    }

    /// An orthographic depth Z -> kernel depth z'.
    #[inline]
    pub fn kernel_depth(&self, z: f64) -> f64 {
        if z.is_finite() {
            self.scale / (self.far - z)
        } else {
            z
        }
    }

    /// World units per kernel tangent unit (S): kernel extents times this
    /// are the orthographic map's half-extents.
    pub fn lateral_scale(&self) -> f64 {
        self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun() -> DirectionalLight {
        DirectionalLight::new([0.8, -0.7, -0.3], [0.0, 0.0, 1.0], [2.0, 1.0]).unwrap()
    }

    #[test]
    fn frame_follows_the_convention() {
        let s = sun();
        assert!((s.n - DVec3::new(0.8, -0.7, -0.3).normalize()).length() < 1e-15);
        assert!(s.u.dot(s.v).abs() < 1e-15 && s.n.dot(s.v).abs() < 1e-15);
        assert!((s.u - s.n.cross(s.v)).length() < 1e-15);
        assert!(s.v.z > 0.0);
        let t = s.half_tangents();
        assert!((t[0] - 1f64.to_radians().tan()).abs() < 1e-15);
    }

    #[test]
    fn degenerate_suns_are_refused() {
        let up = [0.0, 0.0, 1.0];
        assert!(DirectionalLight::new([0.0; 3], up, [1.0, 1.0]).is_err());
        assert!(DirectionalLight::new([0.0, 0.0, -2.0], up, [1.0, 1.0]).is_err());
        assert!(DirectionalLight::new([1.0, 0.0, 0.0], up, [-1.0, 1.0]).is_err());
        assert!(DirectionalLight::new([1.0, 0.0, 0.0], up, [180.0, 1.0]).is_err());
        assert!(DirectionalLight::new([1.0, 0.0, 0.0], up, [0.0, 1.0]).is_err());
        assert!(DirectionalLight::new([1.0, 0.0, 0.0], up, [f64::NAN, 1.0]).is_err());
        assert!(DirectionalLight::new([f64::INFINITY, 0.0, 0.0], up, [1.0, 1.0]).is_err());
        assert!(DirectionalLight::new([1.0, 0.0, 0.0], up, [0.0, 0.0]).is_ok());
    }

    #[test]
    fn the_projective_map_keeps_the_orthographic_back_projection() {
        let pts = [DVec3::new(-1.0, 0.0, 2.0), DVec3::new(3.0, 1.0, -1.0)];
        let sp = SunSpace::fit(sun(), pts.iter().copied()).unwrap();
        for p in pts {
            let z = sp.to_ortho(p).z;
            assert!((-1e-12..=sp.depth_range + 1e-12).contains(&z), "{z}");
        }
        // An occluder point O and a receiver point R: the kernel's tangent
        // (x'_O - x'_R) / (w'_O - w'_R) is the orthographic (X_O - X_R) / (Z_R - Z_O).
        let (o, r) = (DVec3::new(0.3, 0.2, 0.9), DVec3::new(1.1, -0.4, 0.1));
        let (ko, kr) = (sp.to_kernel(o), sp.to_kernel(r));
        let (qo, qr) = (sp.to_ortho(o), sp.to_ortho(r));
        let dw = 1.0 / ko.z - 1.0 / kr.z;
        assert!(dw > 0.0);
        let kx = (ko.x / ko.z - kr.x / kr.z) / dw;
        let ox = (qo.x - qr.x) / (qr.z - qo.z);
        assert!((kx - ox).abs() < 1e-12, "{kx} {ox}");
        // Round trips.
        let back = sp.kernel_to_world(ko.x / ko.z, ko.y / ko.z, ko.z);
        assert!((back - o).length() < 1e-12);
        assert!((sp.kernel_depth(sp.ortho_depth(0.7)) - 0.7).abs() < 1e-15);
        assert_eq!(sp.ortho_depth(f64::INFINITY), f64::INFINITY);
    }
}
