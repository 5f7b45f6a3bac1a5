//! The intersection body B of Scherzer 2005 §4.1 (after Stamminger &
//! Drettakis 2002 and Wimmer et al. 2004): the part of space whose shadows
//! a camera can see.
//!
//! B = (view frustum) ∩ (scene bounds), extended toward the light: every
//! point that can cast a shadow onto a visible point lies on the segment
//! from that point toward the light, inside the scene bounds. A shadow map
//! fitted to B spends no texel on what the camera cannot see.
//!
//! The camera has no near or far plane (it sees every surface in front of
//! it), so its frustum is the pyramid from the eye through the image's
//! outer pixel edges, cut by a far plane just past the scene bounds. Both
//! bodies are convex: every vertex of their intersection lies on a face of
//! one of them, so clipping each one's faces by the other's planes
//! (Sutherland-Hodgman) gives a point set whose convex hull is B.

use super::clip::{clip_polygon, Plane};
use crate::geom::camera::Camera;
use glam::DVec3;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub lo: DVec3,
    pub hi: DVec3,
}

impl Aabb {
    /// The bounds of `points`; `None` for no (finite) point.
    pub fn of(points: impl Iterator<Item = DVec3>) -> Option<Aabb> {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in points.filter(|p| p.is_finite()) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo.cmple(hi).all()).then_some(Aabb { lo, hi })
    }

    pub fn corners(&self) -> [DVec3; 8] {
        let (l, h) = (self.lo, self.hi);
        [
            DVec3::new(l.x, l.y, l.z),
            DVec3::new(h.x, l.y, l.z),
            DVec3::new(h.x, h.y, l.z),
            DVec3::new(l.x, h.y, l.z),
            DVec3::new(l.x, l.y, h.z),
            DVec3::new(h.x, l.y, h.z),
            DVec3::new(h.x, h.y, h.z),
            DVec3::new(l.x, h.y, h.z),
        ]
    }

    /// The six faces as counter-clockwise quads (any winding works for
    /// clipping) and the six inward planes.
    fn faces(&self) -> [[DVec3; 4]; 6] {
        let c = self.corners();
        [
            [c[0], c[1], c[2], c[3]],
            [c[4], c[5], c[6], c[7]],
            [c[0], c[1], c[5], c[4]],
            [c[3], c[2], c[6], c[7]],
            [c[0], c[3], c[7], c[4]],
            [c[1], c[2], c[6], c[5]],
        ]
    }

    fn planes(&self) -> [Plane; 6] {
        // Slightly loose, so that points on a face survive rounding.
        let e = 1e-9 * (self.hi - self.lo).max_element().max(1e-300);
        [
            [1.0, 0.0, 0.0, -self.lo.x + e],
            [-1.0, 0.0, 0.0, self.hi.x + e],
            [0.0, 1.0, 0.0, -self.lo.y + e],
            [0.0, -1.0, 0.0, self.hi.y + e],
            [0.0, 0.0, 1.0, -self.lo.z + e],
            [0.0, 0.0, -1.0, self.hi.z + e],
        ]
    }

    /// Where the ray from `p` (inside) along unit `d` leaves the box.
    pub fn exit(&self, p: DVec3, d: DVec3) -> DVec3 {
        let mut t = f64::INFINITY;
        for a in 0..3 {
            if d[a] > 1e-12 {
                t = t.min((self.hi[a] - p[a]) / d[a]);
            } else if d[a] < -1e-12 {
                t = t.min((self.lo[a] - p[a]) / d[a]);
            }
        }
        p + d * t.max(0.0)
    }
}

/// The camera's frustum as a convex polyhedron: apex at the eye, its far
/// plane just past `bounds`, or at the planar depth `visible` when that is
/// nearer. `None` when the bounds lie wholly behind the camera.
fn frustum(
    camera: &Camera,
    bounds: &Aabb,
    visible: Option<f64>,
) -> Option<(Vec<Vec<DVec3>>, Vec<Plane>)> {
    let far = bounds
        .corners()
        .iter()
        .map(|c| (*c - camera.eye).dot(camera.forward))
        .fold(f64::NEG_INFINITY, f64::max);
    let far = visible.map_or(far, |v| far.min(v));
    if far <= 0.0 {
        return None;
    }
    let far = far * (1.0 + 1e-6) + 1e-9;
    // The image's outer pixel edges (pixel centres at integers).
    let (w, h) = (camera.width as f64, camera.height as f64);
    let edge = |i: f64, j: f64| {
        let (x, y) = (
            (i - camera.cx) / camera.focal,
            -(j - camera.cy) / camera.focal,
        );
        camera.eye + far * (camera.forward + x * camera.right + y * camera.up)
    };
    let q = [
        edge(-0.5, -0.5),
        edge(w - 0.5, -0.5),
        edge(w - 0.5, h - 0.5),
        edge(-0.5, h - 0.5),
    ];
    let e = camera.eye;
    let faces = vec![
        vec![e, q[0], q[1]],
        vec![e, q[1], q[2]],
        vec![e, q[2], q[3]],
        vec![e, q[3], q[0]],
        q.to_vec(),
    ];
    // Inward planes: each face's normal turned toward the far plane's centre.
    let inside = 0.25 * (q[0] + q[1] + q[2] + q[3]) * 0.5 + 0.5 * e;
    let planes = faces
        .iter()
        .map(|f| {
            let n = (f[1] - f[0]).cross(f[2] - f[0]).normalize_or_zero();
            let n = if n.dot(inside - f[0]) < 0.0 { -n } else { n };
            let slack = 1e-9 * far;
            [n.x, n.y, n.z, -n.dot(f[0]) + slack]
        })
        .collect();
    Some((faces, planes))
}

fn clip_all(poly: &[DVec3], planes: &[Plane], out: &mut Vec<DVec3>) {
    let mut cur = poly.to_vec();
    let mut next = Vec::with_capacity(cur.len() + planes.len());
    for p in planes {
        clip_polygon(p, &cur, &mut next);
        std::mem::swap(&mut cur, &mut next);
        if cur.is_empty() {
            return;
        }
    }
    out.extend(cur);
}

/// The vertices of (view frustum) ∩ `bounds`: empty when the camera sees
/// none of the bounds. `visible`, the farthest planar depth (along the
/// camera's axis) of any surface the image sees, cuts the frustum's far
/// plane there: no pixel looks past it, and the occluders beyond it that
/// shadow what is seen are caught by `extend_toward_light`, so the body
/// shrinks to what the image needs (the far cut of sample-distribution
/// shadow maps, Lauritzen et al. 2011; Scherzer's B with the view
/// frustum's far plane pulled in).
pub fn view_body(camera: &Camera, bounds: &Aabb, visible: Option<f64>) -> Vec<DVec3> {
    let Some((f_faces, f_planes)) = frustum(camera, bounds, visible) else {
        return vec![];
    };
    let mut out = vec![];
    for face in bounds.faces() {
        clip_all(&face, &f_planes, &mut out);
    }
    let b_planes = bounds.planes();
    for face in &f_faces {
        clip_all(face, &b_planes, &mut out);
    }
    out
}

/// B's vertices and, for each, where the segment from it toward the light
/// leaves `bounds` (`toward(p)`: the unit direction to the light from p; a
/// rectangle's centre when it lies inside the bounds ends the segment).
pub fn extend_toward_light(
    body: &[DVec3],
    bounds: &Aabb,
    toward: impl Fn(DVec3) -> (DVec3, f64),
) -> Vec<DVec3> {
    let mut out = body.to_vec();
    for &p in body {
        let (d, reach) = toward(p);
        let q = bounds.exit(p, d);
        // A light inside the bounds: the segment ends at the light.
        let q = if (q - p).length() > reach {
            p + d * reach
        } else {
            q
        };
        out.push(q);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::look_at(
            [0.0, 1.0, 5.0],
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            60.0,
            (64, 48),
        )
        .unwrap()
    }

    #[test]
    fn a_box_wholly_in_view_is_its_own_body() {
        let b = Aabb {
            lo: DVec3::splat(-0.2),
            hi: DVec3::splat(0.2),
        };
        let body = view_body(&camera(), &b, None);
        let hull = Aabb::of(body.iter().copied()).unwrap();
        assert!((hull.lo - b.lo).abs().max_element() < 1e-9);
        assert!((hull.hi - b.hi).abs().max_element() < 1e-9);
    }

    #[test]
    fn a_large_box_is_cut_to_the_frustum() {
        let b = Aabb {
            lo: DVec3::new(-100.0, -1.0, -100.0),
            hi: DVec3::new(100.0, 0.0, 100.0),
        };
        // Looking 45 degrees down: the top of the view meets the ground.
        let cam = Camera::look_at(
            [0.0, 5.0, 5.0],
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            60.0,
            (64, 48),
        )
        .unwrap();
        let body = view_body(&cam, &b, None);
        assert!(!body.is_empty());
        // Every vertex is in the box and in front of the eye, inside the
        // image's field of view (with rounding slack).
        let half = (cam.height as f64 / 2.0) / cam.focal;
        for p in &body {
            let d = *p - cam.eye;
            let z = d.dot(cam.forward);
            assert!(z >= -1e-6);
            assert!(d.dot(cam.up) <= (half * 1.01) * z + 1e-6, "{p}");
            assert!(p.y >= -1.0 - 1e-6 && p.y <= 1e-6);
        }
        // The body is much smaller than the box: the camera sees only a
        // patch of the ground.
        let hull = Aabb::of(body.iter().copied()).unwrap();
        assert!(hull.hi.x - hull.lo.x < 150.0);
    }

    #[test]
    fn a_box_behind_the_camera_has_no_body() {
        let b = Aabb {
            lo: DVec3::new(-1.0, -1.0, 10.0),
            hi: DVec3::new(1.0, 1.0, 12.0),
        };
        assert!(view_body(&camera(), &b, None).is_empty());
    }

    #[test]
    fn extension_reaches_the_bounds_toward_the_light() {
        let b = Aabb {
            lo: DVec3::splat(-1.0),
            hi: DVec3::splat(1.0),
        };
        let body = [DVec3::ZERO];
        let ext = extend_toward_light(&body, &b, |_| (DVec3::Y, f64::INFINITY));
        assert_eq!(ext.len(), 2);
        assert!((ext[1] - DVec3::Y).length() < 1e-12);
        let ext = extend_toward_light(&body, &b, |_| (DVec3::Y, 0.5));
        assert!((ext[1] - 0.5 * DVec3::Y).length() < 1e-12);
    }
}
