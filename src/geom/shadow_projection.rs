//! The projections of a standard shadow map (Williams 1978) and of its
//! light-space perspective warp (LiSPSM, Wimmer, Scherzer & Purgathofer
//! 2004; Scherzer 2005 §4.4): the one place that owns their conventions.
//!
//! A projection maps a world point p to clip coordinates
//! `c = M [p, 1]`; the map coordinates are `(u, v) = (c.x, c.y) / c.w` in
//! [-1, 1]² (texel [j, i] of a W×H map centred at
//! `u = -1 + 2(i + 1/2)/W`, `v = 1 - 2(j + 1/2)/H`: row 0 at v = +1), and
//! two depths, both in [0, 1] over the map's depth range:
//! * the *hyperbolic* depth `c.z / c.w`, what a z-buffer holds: for a
//!   perspective map `(f/(f-n)) (1 - n/z)`, steep near the light and flat
//!   far from it; for an orthographic map it equals the linear one;
//! * the *linear* depth `ℓ·[p, 1]`, the distance along the light's axis
//!   (a rectangle's normal, or the sun's direction) mapped affinely onto
//!   [0, 1] (the TSM paper's and Scherzer's linear z-distribution).
//!
//! Light rays keep their map coordinates: from a rectangle's centre (a
//! perspective map along its normal, light coordinates (x, y, z) with
//! (u, v) affine in (x/z, y/z)), or along the sun's direction (an
//! orthographic map; under LiSPSM a perspective one whose view axis is
//! perpendicular to the light, so light rays stay parallel to its image
//! plane and keep their (u, v)). Both depths grow along every light ray.
//!
//! LiSPSM (directional lights). The frame: `L` the light's direction of
//! travel, `Vp = normalize((L × V) × L)` the view vector V (the camera's
//! axis, or Scherzer's *middle vector*: the sum of the vectors from the eye
//! to B's vertices) projected onto the plane normal to L, and
//! `S = L × Vp`. Coordinates of a point: a along Vp, b along S, c along L.
//! The warp P is a perspective frustum looking along Vp from the projection
//! centre C_p, whose (b, c) are the eye's and whose a is B's nearest a
//! minus n (Scherzer eq. 2: its near plane touches B): with
//! `a' = a - a_C ∈ [n, f]`, `f = n + Δa` (B's extent along Vp),
//! `u ∝ b'/a'`, `v = ((f+n) a' - 2 f n) / ((f-n) a')`, `depth ∝ c'/a'`.
//! The free parameter n (Scherzer eq. 1, Wimmer 2004's n_opt) is
//! `n_opt = (z_n + √(z_n z_f)) / sin γ`,
//! γ the angle between L and V, z_n and z_f the nearest and farthest
//! visible depths along the camera's axis (the camera has no clip planes;
//! Scherzer §4.4 derives the far distance from visibility too). As n grows
//! the warp tends to the uniform orthographic map of B in the same frame.
//!
//! Where LiSPSM degenerates: as γ → 0 (light along the view) sin γ → 0 and
//! n_opt → ∞, and Vp itself is undefined at γ = 0. The map then falls back
//! to the uniform one in the light's own frame, and does so as soon as the
//! warp would change texel density across B by less than 2%
//! (`n > FALLBACK_RATIO × Δa`: density along v falls as 1/a'², so the ratio
//! between B's ends is ((n + Δa)/n)² < 1.02), or sin γ < 10⁻³ (γ < 0.057°).

use crate::geom::body::Aabb;
use glam::{DMat4, DVec3, DVec4};

/// LiSPSM's view vector: Wimmer et al.'s (the camera's axis) or Scherzer's
/// middle vector of the intersection body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViewVector {
    Camera,
    Middle,
}

impl ViewVector {
    pub const ALL: [ViewVector; 2] = [ViewVector::Middle, ViewVector::Camera];
    pub fn name(self) -> &'static str {
        match self {
            ViewVector::Camera => "camera",
            ViewVector::Middle => "middle",
        }
    }
    pub fn parse(s: &str) -> Option<ViewVector> {
        Self::ALL.into_iter().find(|v| v.name() == s)
    }
}

/// n larger than this many times B's extent along Vp: the uniform map.
pub const FALLBACK_RATIO: f64 = 100.0;
/// sin γ below this: the uniform map (Vp undefined).
pub const MIN_SIN_GAMMA: f64 = 1e-3;

/// A shadow map's projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowProjection {
    /// World to clip coordinates.
    pub m: DMat4,
    /// The linear depth: `lin.dot([p, 1])`.
    pub lin: DVec4,
    /// Geometry with `c.w` below this is clipped (a perspective map's near
    /// plane; 0 for orthographic maps, whose w is 1).
    pub w_min: f64,
    /// What was built: `Some((n, sin γ))` for a LiSPSM warp, None for a
    /// uniform map (asked for, or the fallback).
    pub warp: Option<(f64, f64)>,
}

/// The map coordinates and both depths of a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    pub u: f64,
    pub v: f64,
    pub hyperbolic: f64,
    pub linear: f64,
    pub w: f64,
}

impl ShadowProjection {
    pub fn project(&self, p: DVec3) -> Projected {
        let h = p.extend(1.0);
        let c = self.m * h;
        Projected {
            u: c.x / c.w,
            v: c.y / c.w,
            hyperbolic: c.z / c.w,
            linear: self.lin.dot(h),
            w: c.w,
        }
    }

    /// A uniform orthographic map along unit `l` (the sun's direction of
    /// travel) whose axes are unit `x` and `y` (orthogonal to `l`), fitted
    /// to `points`.
    pub fn orthographic(l: DVec3, x: DVec3, y: DVec3, points: &[DVec3]) -> Option<Self> {
        let (lo, hi) = bounds(
            points
                .iter()
                .map(|p| DVec3::new(p.dot(x), p.dot(y), p.dot(l))),
        )?;
        let s = (hi - lo).max(DVec3::splat(1e-12 * (hi - lo).max_element().max(1e-300)));
        let row = |axis: DVec3, lo: f64, s: f64, two: f64| {
            // two * (p.axis - lo)/s - (two - 1)
            DVec4::new(
                two * axis.x / s,
                two * axis.y / s,
                two * axis.z / s,
                -two * lo / s - (two - 1.0),
            )
        };
        let rx = row(x, lo.x, s.x, 2.0);
        let ry = row(y, lo.y, s.y, 2.0);
        let rz = row(l, lo.z, s.z, 1.0);
        let m = DMat4::from_cols_array(&[
            rx.x, ry.x, rz.x, 0.0, rx.y, ry.y, rz.y, 0.0, rx.z, ry.z, rz.z, 0.0, rx.w, ry.w, rz.w,
            1.0,
        ]);
        Some(ShadowProjection {
            m,
            lin: rz,
            w_min: 0.0,
            warp: None,
        })
    }

    /// A uniform perspective map from `center` along unit `n` (a
    /// rectangle's centre and normal), axes `x`, `y`, fitted to the points
    /// in front of it. `None` when no point lies in front.
    pub fn perspective(
        center: DVec3,
        n: DVec3,
        x: DVec3,
        y: DVec3,
        points: &[DVec3],
    ) -> Option<Self> {
        let q: Vec<DVec3> = points
            .iter()
            .map(|p| {
                let d = *p - center;
                DVec3::new(d.dot(x), d.dot(y), d.dot(n))
            })
            .collect();
        let far = q.iter().map(|q| q.z).fold(0.0f64, f64::max);
        if !(far > 0.0) {
            return None;
        }
        // A point at or behind the light's plane bounds nothing: the map's
        // near plane is the nearest point in front, at least far * 1e-4
        // (closer geometry is clipped; it can shadow no point in front).
        let near_floor = 1e-4 * far;
        let near = q
            .iter()
            .filter(|q| q.z > 0.0)
            .map(|q| q.z)
            .fold(far, f64::min)
            .max(near_floor);
        let (lo, hi) = bounds(
            q.iter()
                .filter(|q| q.z > 0.0)
                .map(|q| DVec3::new(q.x / q.z.max(near), q.y / q.z.max(near), 0.0)),
        )?;
        let s = (hi - lo).max(DVec3::splat(1e-12));
        let (f, nn) = (far * (1.0 + 1e-7), near * (1.0 - 1e-7));
        // Light coordinates, then clip: x_c = (2 x - (lo+hi) z)/s, w = z,
        // z_c = f/(f-n) (z - n).
        let light = DMat4::from_cols(
            DVec4::new(x.x, y.x, n.x, 0.0),
            DVec4::new(x.y, y.y, n.y, 0.0),
            DVec4::new(x.z, y.z, n.z, 0.0),
            DVec4::new(-x.dot(center), -y.dot(center), -n.dot(center), 1.0),
        );
        let k = f / (f - nn);
        let proj = DMat4::from_cols(
            DVec4::new(2.0 / s.x, 0.0, 0.0, 0.0),
            DVec4::new(0.0, 2.0 / s.y, 0.0, 0.0),
            DVec4::new(-(lo.x + hi.x) / s.x, -(lo.y + hi.y) / s.y, k, 1.0),
            DVec4::new(0.0, 0.0, -k * nn, 0.0),
        );
        let m = proj * light;
        // Linear: (z - n)/(f - n), z = n.(p - center).
        let lin = DVec4::new(n.x, n.y, n.z, -n.dot(center) - nn) / (f - nn);
        Some(ShadowProjection {
            m,
            lin,
            w_min: nn,
            warp: None,
        })
    }

    /// LiSPSM for a directional light travelling along unit `l`, seen by a
    /// camera at `eye` with view vector `view` (unit), fitted to the
    /// extended body `body`; `n` the warp's parameter (None: n_opt from the
    /// visible depths `z_near`, `z_far` along the camera's axis). Falls
    /// back to `fallback` (the uniform map) where LiSPSM degenerates (the
    /// module doc).
    #[allow(clippy::too_many_arguments)]
    pub fn lispsm(
        l: DVec3,
        eye: DVec3,
        view: DVec3,
        body: &[DVec3],
        n: Option<f64>,
        z_near: f64,
        z_far: f64,
        fallback: ShadowProjection,
    ) -> ShadowProjection {
        let sin_gamma = l.cross(view).length();
        if sin_gamma < MIN_SIN_GAMMA {
            return fallback;
        }
        let vp = (view - view.dot(l) * l).normalize();
        let s = l.cross(vp);
        let coords = |p: DVec3| DVec3::new(p.dot(vp), p.dot(s), p.dot(l));
        let Some((lo, hi)) = bounds(body.iter().map(|p| coords(*p))) else {
            return fallback;
        };
        let delta = (hi.x - lo.x).max(1e-12 * hi.abs().max_element().max(1.0));
        let n = n.unwrap_or_else(|| n_opt(z_near, z_far, sin_gamma));
        if !(n.is_finite() && n > 0.0) || n > FALLBACK_RATIO * delta {
            return fallback;
        }
        let e = coords(eye);
        let c = DVec3::new(lo.x - n, e.y, e.z);
        let f = n + delta;
        // a' = a - c.a, b' = b - c.b, c' = c - c.c.
        let rel: Vec<DVec3> = body.iter().map(|p| coords(*p) - c).collect();
        let (blo, bhi) = bounds(rel.iter().map(|r| DVec3::new(r.y / r.x, r.z / r.x, 0.0)))
            .expect("a non-empty body");
        let sb = (bhi.x - blo.x).max(1e-12);
        let sk = (bhi.y - blo.y).max(1e-12);
        // In (a', b', c', 1): clip x = (2 b' - (b0 + b1) a')/sb,
        // y = ((f+n) a' - 2 f n)/(f-n), z = (c' - k0 a')/sk, w = a'.
        let warp = DMat4::from_cols(
            DVec4::new(-(blo.x + bhi.x) / sb, (f + n) / (f - n), -blo.y / sk, 1.0),
            DVec4::new(2.0 / sb, 0.0, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 1.0 / sk, 0.0),
            DVec4::new(0.0, -2.0 * f * n / (f - n), 0.0, 0.0),
        );
        // World -> (a', b', c', 1).
        let frame = DMat4::from_cols(
            DVec4::new(vp.x, s.x, l.x, 0.0),
            DVec4::new(vp.y, s.y, l.y, 0.0),
            DVec4::new(vp.z, s.z, l.z, 0.0),
            DVec4::new(-c.x, -c.y, -c.z, 1.0),
        );
        let sc = (hi.z - lo.z).max(1e-12);
        let lin = DVec4::new(l.x, l.y, l.z, -lo.z) / sc;
        ShadowProjection {
            m: warp * frame,
            lin,
            w_min: n * (1.0 - 1e-9),
            warp: Some((n, sin_gamma)),
        }
    }
}

/// Scherzer 2005 eq. 1 (Wimmer et al. 2004): the warp parameter that
/// balances perspective aliasing between the visible range's ends.
pub fn n_opt(z_near: f64, z_far: f64, sin_gamma: f64) -> f64 {
    let zn = z_near.max(1e-9);
    let zf = z_far.max(zn);
    (zn + (zn * zf).sqrt()) / sin_gamma
}

fn bounds(points: impl Iterator<Item = DVec3>) -> Option<(DVec3, DVec3)> {
    Aabb::of(points).map(|b| (b.lo, b.hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_points() -> Vec<DVec3> {
        let mut v = vec![];
        for i in 0..5 {
            for j in 0..5 {
                for k in 0..3 {
                    v.push(DVec3::new(
                        i as f64 - 2.0,
                        k as f64 * 0.5,
                        j as f64 * 3.0 - 20.0,
                    ));
                }
            }
        }
        v
    }

    #[test]
    fn orthographic_maps_the_points_onto_the_unit_square() {
        let pts = grid_points();
        let p = ShadowProjection::orthographic(-DVec3::Y, DVec3::X, DVec3::Z, &pts).unwrap();
        for q in &pts {
            let r = p.project(*q);
            assert!(r.u.abs() <= 1.0 + 1e-9 && r.v.abs() <= 1.0 + 1e-9);
            assert!((r.hyperbolic - r.linear).abs() < 1e-12);
            assert!((-1e-9..=1.0 + 1e-9).contains(&r.linear));
        }
    }

    #[test]
    fn perspective_depths_are_hyperbolic_and_linear() {
        let pts = vec![
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.5, 0.5, 3.0),
            DVec3::new(-0.5, 0.0, 2.0),
        ];
        let p =
            ShadowProjection::perspective(DVec3::ZERO, DVec3::Z, DVec3::X, DVec3::Y, &pts).unwrap();
        let a = p.project(DVec3::new(0.0, 0.0, 1.0));
        let b = p.project(DVec3::new(0.0, 0.0, 2.0));
        let c = p.project(DVec3::new(0.0, 0.0, 3.0));
        assert!(a.linear.abs() < 1e-6 && (c.linear - 1.0).abs() < 1e-6);
        assert!((b.linear - 0.5).abs() < 1e-6);
        // (f/(f-n))(1 - n/z) at z = 2: 1.5 * 0.5 = 0.75.
        assert!((b.hyperbolic - 0.75).abs() < 1e-6, "{}", b.hyperbolic);
        // Along a ray from the centre u, v stay put.
        let d = p.project(DVec3::new(0.25, 0.125, 1.0));
        let e = p.project(DVec3::new(0.5, 0.25, 2.0));
        assert!((d.u - e.u).abs() < 1e-12 && (d.v - e.v).abs() < 1e-12);
    }

    #[test]
    fn n_opt_at_a_right_angle_is_the_closed_form() {
        // Wimmer et al. 2004: n_opt = z_n + sqrt(z_n z_f) at γ = 90°; and
        // the general form d / (sqrt(z1/z0) - 1), z1 = z0 + d sin γ (the
        // authors' 2006 code), agrees with it there.
        let (zn, zf) = (0.5f64, 40.0f64);
        let closed = zn + (zn * zf).sqrt();
        assert!((n_opt(zn, zf, 1.0) - closed).abs() < 1e-12);
        let d = zf - zn;
        let general = d / (((zn + d) / zn).sqrt() - 1.0);
        assert!((general - closed).abs() < 1e-9 * closed);
        // It grows as 1/sin γ.
        assert!((n_opt(zn, zf, 0.5) - 2.0 * closed).abs() < 1e-12);
    }

    fn sun_setup() -> (DVec3, DVec3, DVec3, Vec<DVec3>, ShadowProjection) {
        let l = DVec3::new(0.3, -1.0, 0.2).normalize();
        let eye = DVec3::new(0.0, 1.0, 0.0);
        let view = DVec3::new(0.0, -0.1, -1.0).normalize();
        let pts = grid_points();
        let vp = (view - view.dot(l) * l).normalize();
        let s = l.cross(vp);
        let uniform = ShadowProjection::orthographic(l, s, vp, &pts).unwrap();
        (l, eye, view, pts, uniform)
    }

    #[test]
    fn lispsm_keeps_light_rays_and_orders_depth_along_them() {
        let (l, eye, view, pts, uniform) = sun_setup();
        let p = ShadowProjection::lispsm(l, eye, view, &pts, None, 1.0, 30.0, uniform);
        assert!(p.warp.is_some());
        for q in &pts {
            let a = p.project(*q);
            let b = p.project(*q + 0.7 * l);
            assert!((a.u - b.u).abs() < 1e-9 && (a.v - b.v).abs() < 1e-9);
            assert!(b.hyperbolic > a.hyperbolic && b.linear > a.linear);
            assert!(a.u.abs() <= 1.0 + 1e-9 && a.v.abs() <= 1.0 + 1e-9);
            assert!((-1e-9..=1.0 + 1e-9).contains(&a.hyperbolic));
        }
    }

    #[test]
    fn lispsm_gives_more_texels_near_the_eye() {
        let (l, eye, view, pts, uniform) = sun_setup();
        let p = ShadowProjection::lispsm(l, eye, view, &pts, None, 1.0, 30.0, uniform);
        // Two equal steps along the view, near and far: the near one spans
        // more of the map.
        let step = |z: f64| {
            let a = p.project(DVec3::new(0.0, 0.0, z));
            let b = p.project(DVec3::new(0.0, 0.0, z - 1.0));
            (a.u - b.u).hypot(a.v - b.v)
        };
        assert!(
            step(-1.0) > 3.0 * step(-18.0),
            "{} {}",
            step(-1.0),
            step(-18.0)
        );
    }

    #[test]
    fn lispsm_tends_to_the_uniform_map_as_n_grows() {
        let (l, eye, view, pts, uniform) = sun_setup();
        let mut last = f64::INFINITY;
        for n in [1.0, 10.0, 100.0, 1000.0] {
            let p = ShadowProjection::lispsm(l, eye, view, &pts, Some(n), 1.0, 30.0, uniform);
            assert!(p.warp.is_some(), "n = {n}");
            // Compare map positions with the uniform map of the same frame
            // (LiSPSM's v runs along Vp, the uniform map's v too).
            let worst = pts
                .iter()
                .map(|q| {
                    let (a, b) = (p.project(*q), uniform.project(*q));
                    (a.u - b.u).abs().max((a.v - b.v).abs())
                })
                .fold(0.0f64, f64::max);
            assert!(worst < last, "n = {n}: {worst} !< {last}");
            last = worst;
        }
        assert!(last < 0.05, "{last}");
        // Past the fallback ratio the uniform map itself is returned.
        let p = ShadowProjection::lispsm(l, eye, view, &pts, Some(1e9), 1.0, 30.0, uniform);
        assert_eq!(p, uniform);
    }

    #[test]
    fn lispsm_falls_back_when_the_light_is_along_the_view() {
        let (_, eye, view, pts, uniform) = sun_setup();
        let p = ShadowProjection::lispsm(view, eye, view, &pts, None, 1.0, 30.0, uniform);
        assert_eq!(p, uniform);
        // Nearly parallel: n_opt is huge, past the fallback ratio.
        let l = (view + 2e-3 * DVec3::X).normalize();
        let p = ShadowProjection::lispsm(l, eye, view, &pts, None, 1.0, 30.0, uniform);
        assert_eq!(p, uniform);
    }
}
