//! The light's shape in its own plane: the one type every stage asks about
//! the light, so that a new shape (a disk, a sphere's silhouette) is this
//! module (a variant here, its facts in a file beside `rect.rs`) plus the
//! kernels' sampling and clipping.
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
//! * **In front of a plane** (the eye view's tangent-plane bound,
//!   eye/tangent_plane.rs): the fraction of the light where
//!   a0 + a1 x + a2 y >= 0 (`LightShape::front_fraction`; the rectangle's
//!   closed form in rect.rs).
//!
//! Each quantity is computed here in the order the kernels always did (in
//! f64, rounded once to f32), so moving it here changed no bit.

pub(crate) mod disk;
pub(crate) mod disk_clip;
mod placement;
mod rect;
pub(crate) mod sphere;
#[cfg(test)]
mod test_rng;

use crate::error::{Error, Result};
use crate::geom::units::{MAX_RELATIVE_SIZE, MIN_RELATIVE_SIZE};
use glam::DVec3;
pub use placement::Placement;

/// The shape of a light in its plane (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightShape {
    /// Full width along u and full height along v; [0, 0]: a point light.
    Rect { size: [f64; 2] },
    /// The disk of this radius about the origin (disk.rs).
    Disk { radius: f64 },
}

impl LightShape {
    /// A point light: the rectangle of size 0.
    pub const POINT: LightShape = LightShape::Rect { size: [0.0, 0.0] };

    /// The rectangle of full width and height `size`, unchecked (`check`).
    pub const fn rect(size: [f64; 2]) -> LightShape {
        LightShape::Rect { size }
    }

    /// The disk of `radius`, unchecked (`check`).
    pub const fn disk(radius: f64) -> LightShape {
        LightShape::Disk { radius }
    }

    /// What the shape is called in messages ("rectangle", "disk").
    pub fn name(&self) -> &'static str {
        match self {
            LightShape::Rect { .. } => "rectangle",
            LightShape::Disk { .. } => "disk",
        }
    }

    /// The shape, or an error naming `arg`: a rectangle's sides both finite
    /// and > 0, or both 0 (a point light).
    pub fn check(self, arg: &str) -> Result<LightShape> {
        let size = match self {
            LightShape::Rect { size } => size,
            LightShape::Disk { radius } if radius.is_finite() && radius > 0.0 => return Ok(self),
            LightShape::Disk { radius } => {
                return Err(Error::invalid(
                    arg,
                    format!("must be a finite radius > 0, got {radius}"),
                ))
            }
        };
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
        matches!(self, LightShape::Rect { size } if *size == [0.0, 0.0])
    }

    /// The shape with every length divided by `unit` (a power of two:
    /// exact, units.rs), refused when the kernels cannot resolve it: a
    /// ratio to the receivers' depth outside [MIN_RELATIVE_SIZE,
    /// MAX_RELATIVE_SIZE] makes 2/L or L/2 leave the f32 range.
    pub fn in_unit(&self, arg: &str, unit: f64) -> Result<LightShape> {
        if self.is_point() {
            return Ok(LightShape::POINT);
        }
        let size = self.extent();
        let s = [size[0] / unit, size[1] / unit];
        if s.iter()
            .all(|x| (MIN_RELATIVE_SIZE..=MAX_RELATIVE_SIZE).contains(x))
        {
            return Ok(match *self {
                LightShape::Rect { .. } => LightShape::rect(s),
                LightShape::Disk { radius } => LightShape::disk(radius / unit),
            });
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
        match *self {
            LightShape::Rect { size } => size,
            LightShape::Disk { radius } => [2.0 * radius; 2],
        }
    }

    /// The half-extents (hx, hy) = (sx/2, sy/2): every light point has
    /// |x| <= hx, |y| <= hy; the penumbra reach is h (1/z - 1/z_r).
    pub fn half_extent(&self) -> [f64; 2] {
        let size = self.extent();
        [0.5 * size[0], 0.5 * size[1]]
    }

    /// The light's area.
    pub fn area(&self) -> f64 {
        match *self {
            LightShape::Rect { size } => size[0] * size[1],
            LightShape::Disk { radius } => std::f64::consts::PI * radius * radius,
        }
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
        let size = self.extent();
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
        LightSamples {
            grid: self.sample_grid(samples),
            size: self.extent().map(|s| s as f32),
            disk: matches!(self, LightShape::Disk { .. }),
        }
    }

    /// The map kernels' half-light units, in f32.
    pub fn half_light(&self) -> HalfLight {
        let size = self.extent();
        HalfLight {
            inv_half: [(2.0 / size[0]) as f32, (2.0 / size[1]) as f32],
            half: [(0.5 * size[0]) as f32, (0.5 * size[1]) as f32],
        }
    }

    /// An f32 tangent x in half-light units, scaled in f64 and rounded once
    /// (`x * 2 / sx`; the kernels' column edges, CPU and GPU alike).
    pub fn x_in_half_light(&self, x: f32) -> f32 {
        (x as f64 * 2.0 / self.extent()[0]) as f32
    }

    /// The unoccluded irradiance at `x` (unit normal `n`) from this shape of
    /// unit radiance placed at `at`: its form factor (module doc; the
    /// rectangle's is Lambert's polygon formula after horizon clipping).
    pub fn irradiance(&self, at: &Placement, x: DVec3, n: DVec3) -> f64 {
        match *self {
            LightShape::Rect { size } => rect::irradiance(size, at, x, n),
            LightShape::Disk { radius } => disk::irradiance(radius, at, x, n),
        }
    }

    /// The plane's normal `n` turned toward this shape placed at `at` when
    /// the whole light lies strictly on one side of the plane (through
    /// `p0`), farther than `tol`; None when the light meets the plane.
    pub fn strict_side(&self, at: &Placement, p0: DVec3, n: DVec3, tol: f64) -> Option<DVec3> {
        match *self {
            LightShape::Rect { size } => rect::strict_side(size, at, p0, n, tol),
            LightShape::Disk { radius } => disk::strict_side(radius, at, p0, n, tol),
        }
    }

    /// The fraction of the light (kernel units, centred) where
    /// `side[0] + side[1] x + side[2] y >= 0`: the light clipped by a plane
    /// (a point light is its centre).
    pub fn front_fraction(&self, side: [f64; 3]) -> f64 {
        match self {
            LightShape::Rect { .. } => rect::front_fraction(side, self.half_extent()),
            LightShape::Disk { radius } => disk::front_fraction(side, *radius),
        }
    }
}

/// Where the rays of a receiver go on the light, in f32 (the ray casters'
/// inner loops; `gpu/light_shape.wgsl` is the device's twin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSamples {
    /// The strata a x b (`LightShape::sample_grid`).
    pub grid: (u32, u32),
    /// The rectangle's full width and height; a disk's diameter, twice.
    pub size: [f32; 2],
    /// The strata are mapped onto the disk inscribed in `size` (Shirley and
    /// Chiu's concentric map, disk.rs: equal strata stay equal in area).
    pub disk: bool,
}

impl LightSamples {
    /// The light point of stratum (sa, sb) jittered by (ja, jb) in [0, 1)^2:
    /// (((sa + ja)/a - 1/2) sx, ((sb + jb)/b - 1/2) sy).
    #[inline(always)]
    pub fn point(&self, sa: u32, sb: u32, ja: f32, jb: f32) -> (f32, f32) {
        if self.disk {
            return disk::sample_point(0.5 * self.size[0], self.grid, sa, sb, ja, jb);
        }
        let (na, nb) = self.grid;
        let x = ((sa as f32 + ja) / na as f32 - 0.5) * self.size[0];
        let y = ((sb as f32 + jb) / nb as f32 - 0.5) * self.size[1];
        (x, y)
    }

    /// The box [[x0, x1], [y0, y1]] holding every sample of strata
    /// [a0, a1) x [b0, b1) (the shaft culling's target).
    pub fn region(&self, a0: u32, a1: u32, b0: u32, b1: u32) -> [[f32; 2]; 2] {
        if self.disk {
            // The concentric map bends a block of strata into a sector of
            // an annulus; the disk's box holds it (a looser shaft only
            // traces more rays, each with the same answer).
            let r = 0.5 * self.size[0];
            return [[-r, r], [-r, r]];
        }
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
