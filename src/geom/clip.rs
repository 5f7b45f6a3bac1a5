//! Clip planes in light space and Sutherland-Hodgman clipping of a triangle
//! against them. An edge's intersection with a plane is computed from its
//! endpoints in a canonical (lexicographic) order, so that two triangles
//! sharing the edge get the same point bit for bit and stay watertight.

use glam::DVec3;

/// A clip plane in light space: keep points where a.X + b.Y + c.Z + d >= 0.
pub(crate) type Plane = [f64; 4];

pub(crate) fn plane_dist(p: &Plane, q: DVec3) -> f64 {
    p[0] * q.x + p[1] * q.y + p[2] * q.z + p[3]
}

fn lex_less(a: DVec3, b: DVec3) -> bool {
    (a.x, a.y, a.z) < (b.x, b.y, b.z)
}

/// Intersection of segment ab with plane p, computed from the lexicographically
/// smaller endpoint so that both triangles sharing the edge agree bit for bit.
fn clip_point(p: &Plane, a: DVec3, b: DVec3) -> DVec3 {
    let (s, e) = if lex_less(a, b) { (a, b) } else { (b, a) };
    let ds = plane_dist(p, s);
    let de = plane_dist(p, e);
    let t = ds / (ds - de);
    s + (e - s) * t
}

/// Sutherland-Hodgman against one plane. `out` is cleared first.
pub(crate) fn clip_polygon(p: &Plane, poly: &[DVec3], out: &mut Vec<DVec3>) {
    out.clear();
    let n = poly.len();
    for k in 0..n {
        let a = poly[k];
        let b = poly[(k + 1) % n];
        let da = plane_dist(p, a);
        let db = plane_dist(p, b);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(clip_point(p, a, b));
        }
    }
}
