//! Light space: the one place that owns the conventions.
//!
//! * Light frame: `n = normalize(normal)` points from the light into the scene,
//!   `v = normalize(up - (up.n) n)`, `u = n x v`. `size = (sx, sy)` is the full
//!   width along `u` and the full height along `v`. (u, v, n) is left-handed,
//!   like a camera looking along +n with u to the right and v up.
//! * Light space coordinates of a world point p: `(X, Y, Z) = ((p-c).u, (p-c).v, (p-c).n)`.
//!   `Z` is the planar depth (distance from the light's plane along n).
//! * Tangent coordinates: `(x, y) = (X/Z, Y/Z)`; a direction `n + x u + y v`.
//! * A light-view map of shape (H, W): texel [j, i] has center direction
//!   `n + x u + y v` with `x = (-1 + 2(i+1/2)/W) tx`, `y = (1 - 2(j+1/2)/H) ty`:
//!   u to the right, v up, row 0 is the +v edge. `(tx, ty)` are the tangent half-extents.
//!
//! World -> light transforms run in f64 (a scene far from the origin loses its
//! shape in f32); maps and kernels work in f32 once coordinates are light-relative.

use crate::error::{Error, Result};
use crate::geom::light_shape::{LightShape, Placement};
use glam::DVec3;

/// A planar area light (a rectangle or a disk, `LightShape`) with its
/// orthonormal frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaLight {
    pub center: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub n: DVec3,
    /// Its shape in its plane, centred on `center` (a rectangle's full
    /// width along u and height along v, a disk's radius).
    pub shape: LightShape,
}

/// A finite 3-vector, or an error naming `arg`.
pub(crate) fn finite3(arg: &str, a: [f64; 3]) -> Result<DVec3> {
    if a.iter().all(|x| x.is_finite()) {
        Ok(DVec3::from_array(a))
    } else {
        Err(Error::invalid(arg, format!("must be finite, got {a:?}")))
    }
}

/// The `up` of a disk facing `normal`: the world axis with the smallest
/// component along it (never parallel to a non-zero normal; ties go to the
/// first axis, so the frame is the same for the same normal).
pub(crate) fn disk_up(normal: DVec3) -> [f64; 3] {
    let a = normal.abs();
    if a.x <= a.y && a.x <= a.z {
        [1.0, 0.0, 0.0]
    } else if a.y <= a.z {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// A light's frame (u, v, n) from its axis `axis` (named `axis_arg`: the
/// rectangle's "normal", the sun's "direction") and `up`:
/// `n = normalize(axis)`, `v = normalize(up - (up.n) n)`, `u = n x v`,
/// refusing non-finite or zero vectors and an `up` along the axis.
pub(crate) fn light_frame(
    axis_arg: &str,
    axis: [f64; 3],
    up: [f64; 3],
) -> Result<(DVec3, DVec3, DVec3)> {
    let nrm = finite3(axis_arg, axis)?;
    let up = finite3("up", up)?;
    let nlen = nrm.length();
    if !(nlen > 1e-300) || !nlen.is_finite() {
        return Err(Error::invalid(axis_arg, "has zero length"));
    }
    let n = nrm / nlen;
    let ulen = up.length();
    if !(ulen > 1e-300) || !ulen.is_finite() {
        return Err(Error::invalid("up", "has zero length"));
    }
    let ortho = up - up.dot(n) * n;
    // Relative test: `up` within ~1e-6 rad of the axis gives no usable v axis.
    if ortho.length() <= 1e-6 * ulen {
        return Err(Error::invalid(
            "up",
            format!(
                "is parallel to {axis_arg}: it must have a component across the light's {axis_arg}"
            ),
        ));
    }
    let v = ortho.normalize();
    Ok((n.cross(v), v, n))
}

impl AreaLight {
    /// The light's shape in its plane.
    pub fn shape(&self) -> LightShape {
        self.shape
    }

    /// Where its shape lies in the world: its centre and frame.
    pub fn placement(&self) -> Placement {
        Placement {
            center: self.center,
            u: self.u,
            v: self.v,
            n: self.n,
        }
    }

    /// The unoccluded irradiance at world point `x` (unit normal `n`) from
    /// the light of unit radiance: its shape's form factor there
    /// (`LightShape::irradiance`; 0 at or behind its plane, or for a point
    /// light).
    pub fn irradiance(&self, x: DVec3, n: DVec3) -> f64 {
        self.shape().irradiance(&self.placement(), x, n)
    }

    /// The normal `n` of the plane through `p0` turned toward the light
    /// when the whole light lies strictly on one side of it (farther than
    /// `tol`); None when the light meets the plane (`LightShape::strict_side`).
    pub fn strict_side(&self, p0: DVec3, n: DVec3, tol: f64) -> Option<DVec3> {
        self.shape().strict_side(&self.placement(), p0, n, tol)
    }

    /// A rectangle of full width and height `size` (both 0: a point light),
    /// refusing degenerate input.
    pub fn rect(center: [f64; 3], normal: [f64; 3], up: [f64; 3], size: [f64; 2]) -> Result<Self> {
        AreaLight::new(center, normal, up, LightShape::rect(size), "size")
    }

    /// A disk of `radius` (> 0, finite) facing `normal`. A disk looks the
    /// same turned about its axis, so its frame's `up` is chosen here: the
    /// world axis least aligned with the normal (`disk_up`).
    pub fn disk(center: [f64; 3], normal: [f64; 3], radius: f64) -> Result<Self> {
        let up = disk_up(finite3("normal", normal)?);
        AreaLight::new(center, normal, up, LightShape::disk(radius), "radius")
    }

    /// The light of `shape` (checked, named `shape_arg`) in the frame of
    /// `normal` and `up` at `center`.
    fn new(
        center: [f64; 3],
        normal: [f64; 3],
        up: [f64; 3],
        shape: LightShape,
        shape_arg: &str,
    ) -> Result<Self> {
        let c = finite3("center", center)?;
        let (u, v, n) = light_frame("normal", normal, up)?;
        Ok(AreaLight {
            center: c,
            u,
            v,
            n,
            shape: shape.check(shape_arg)?,
        })
    }

    /// A light in the canonical frame: center at the origin, n = +z, v = +y (so u = -x).
    /// Used when the user hands us depth maps and no light position.
    pub fn canonical(size: [f64; 2]) -> Result<Self> {
        AreaLight::rect([0.0; 3], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], size)
    }

    /// World point -> light space (X, Y, Z), in f64.
    #[inline]
    pub fn to_light(&self, p: DVec3) -> DVec3 {
        let d = p - self.center;
        DVec3::new(d.dot(self.u), d.dot(self.v), d.dot(self.n))
    }

    /// Light space (X, Y, Z) -> world point.
    #[inline]
    pub fn to_world(&self, q: DVec3) -> DVec3 {
        self.center + q.x * self.u + q.y * self.v + q.z * self.n
    }

    /// The world point at planar depth `z` along tangent direction (x, y).
    #[inline]
    pub fn point_at(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.to_world(DVec3::new(x * z, y * z, z))
    }
}

/// The texel grid of a light-view map: resolution and tangent half-extents.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapGrid {
    pub width: usize,
    pub height: usize,
    pub tx: f64,
    pub ty: f64,
}

/// The largest map we agree to allocate (texels per map). Four f32 maps of this
/// size take 4 GiB; beyond it we refuse before allocating.
pub const MAX_TEXELS: usize = 1 << 28;

/// The widest tangent half-extent we accept (89.99994 degrees off the axis).
/// The kernels hold tangents in f32 and multiply them by depths: far beyond
/// this, texel positions overflow and shadows silently vanish.
pub const MAX_EXTENT: f64 = 1e6;

/// A map resolution (W, H): at least 1x1, at most MAX_TEXELS texels.
pub fn check_resolution(arg: &str, (w, h): (i64, i64)) -> Result<(usize, usize)> {
    if w < 1 || h < 1 {
        return Err(Error::invalid(
            arg,
            format!("must be at least 1x1, got {w}x{h}"),
        ));
    }
    let texels = (w as u128) * (h as u128);
    if texels > MAX_TEXELS as u128 {
        return Err(Error::too_large(
            arg,
            format!(
                "{w}x{h} would need {} bytes per map (limit {MAX_TEXELS} texels)",
                texels * 4
            ),
        ));
    }
    Ok((w as usize, h as usize))
}

impl MapGrid {
    pub fn new(width: usize, height: usize, extent: [f64; 2]) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::invalid(
                "resolution",
                format!("must be at least 1x1, got {width}x{height}"),
            ));
        }
        let texels = width.saturating_mul(height);
        if texels > MAX_TEXELS {
            return Err(Error::too_large(
                "resolution",
                format!(
                    "{width}x{height} would need {} bytes per map (limit {} texels)",
                    texels as u128 * 4,
                    MAX_TEXELS
                ),
            ));
        }
        if !extent.iter().all(|t| t.is_finite() && *t > 0.0) {
            return Err(Error::invalid(
                "extent",
                format!("must be two finite tangent half-extents > 0, got {extent:?}"),
            ));
        }
        if extent.iter().any(|t| *t > MAX_EXTENT) {
            return Err(Error::invalid(
                "extent",
                format!("tangent half-extents must be <= {MAX_EXTENT:e}, got {extent:?}"),
            ));
        }
        Ok(MapGrid {
            width,
            height,
            tx: extent[0],
            ty: extent[1],
        })
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Tangent x of the center of column i.
    #[inline]
    pub fn x_of(&self, i: usize) -> f64 {
        (-1.0 + 2.0 * (i as f64 + 0.5) / self.width as f64) * self.tx
    }

    /// Tangent y of the center of row j (row 0 is the +v edge).
    #[inline]
    pub fn y_of(&self, j: usize) -> f64 {
        (1.0 - 2.0 * (j as f64 + 0.5) / self.height as f64) * self.ty
    }

    /// Half the width and half the height of a texel, in tangent units.
    #[inline]
    pub fn half_texel(&self) -> (f64, f64) {
        (self.tx / self.width as f64, self.ty / self.height as f64)
    }

    /// Tangent (x, y) -> continuous pixel coordinates (px right, py down; texel
    /// [j, i] covers px in [i, i+1], py in [j, j+1]).
    #[inline]
    pub fn to_pixel(&self, x: f64, y: f64) -> (f64, f64) {
        (
            (x / self.tx + 1.0) * 0.5 * self.width as f64,
            (1.0 - y / self.ty) * 0.5 * self.height as f64,
        )
    }

    /// The tangent x of every column center, in f32 (the kernels' inner loops read it).
    pub fn column_centers(&self) -> Vec<f32> {
        (0..self.width).map(|i| self.x_of(i) as f32).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_follows_the_convention() {
        let l = AreaLight::rect(
            [0.0, 4.0, 0.0],
            [0.0, -2.0, 0.0],
            [0.0, 0.3, 1.0],
            [1.0, 2.0],
        )
        .unwrap();
        assert!((l.n - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-15);
        assert!((l.v - DVec3::new(0.0, 0.0, 1.0)).length() < 1e-15);
        // u = n x v = (0,-1,0) x (0,0,1) = (-1, 0, 0)
        assert!((l.u - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-15);
        let p = DVec3::new(0.3, 1.0, -0.2);
        let q = l.to_light(p);
        assert!((l.to_world(q) - p).length() < 1e-12);
        assert!((q.z - 3.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_lights_are_refused() {
        let ok = ([0.0; 3], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 1.0]);
        assert!(AreaLight::rect(ok.0, [0.0; 3], ok.2, ok.3).is_err());
        assert!(AreaLight::rect(ok.0, ok.1, [0.0, 0.0, 5.0], ok.3).is_err());
        assert!(AreaLight::rect(ok.0, ok.1, ok.2, [0.0, 1.0]).is_err());
        assert!(AreaLight::rect(ok.0, ok.1, ok.2, [-0.0, 0.0]).is_ok()); // a point light
        assert!(AreaLight::rect(ok.0, ok.1, ok.2, [1.0, f64::NAN]).is_err());
        assert!(AreaLight::rect([f64::INFINITY, 0.0, 0.0], ok.1, ok.2, ok.3).is_err());
    }

    #[test]
    fn texel_centers_follow_the_convention() {
        let g = MapGrid::new(4, 2, [1.0, 0.5]).unwrap();
        assert_eq!(g.x_of(0), -0.75);
        assert_eq!(g.x_of(3), 0.75);
        assert_eq!(g.y_of(0), 0.25);
        assert_eq!(g.y_of(1), -0.25);
        let (px, py) = g.to_pixel(g.x_of(2), g.y_of(1));
        assert_eq!((px, py), (2.5, 1.5));
    }

    #[test]
    fn absurd_resolutions_are_refused_before_allocating() {
        assert!(MapGrid::new(0, 5, [1.0, 1.0]).is_err());
        assert!(matches!(
            MapGrid::new(1 << 20, 1 << 20, [1.0, 1.0]),
            Err(Error::TooLarge { .. })
        ));
        assert!(MapGrid::new(8, 8, [0.0, 1.0]).is_err());
        assert!(MapGrid::new(8, 8, [1.0, 2e6]).is_err());
        assert!(MapGrid::new(8, 8, [50.0, 1e6]).is_ok());
    }
}
