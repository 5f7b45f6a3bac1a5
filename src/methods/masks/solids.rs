//! Large closed pieces (a tessellated sphere, a cylinder, a capsule, a
//! convex hull): each one's shadow on the light from an origin found from
//! its silhouette, one convex polygon cut into covers, instead of the
//! union of its (thousands of) triangles' shadows.
//!
//! A solid is a run of consecutive input triangles too long for a
//! `pieces` piece (more than `MAX_TRIANGLES`) that closes a surface of the
//! sphere's topology (every edge, corners matched bit for bit, shared by
//! two triangles winding it opposite ways; V - E + F = 2), convex at every
//! edge (each triangle's neighbours' far corners on its inner side, within
//! a relative 1e-6). Nothing global is assumed from that: the per-origin
//! test below is what makes the outline exact.
//!
//! Why it is exact. Let o (a ray origin) and the light lie outside the
//! solid: every corner deeper than the light and shallower than o by the
//! margins `cover::cover` drops its end planes for (then every crossing
//! has t in (t0, t1) too). Orient the triangles outward; call a triangle
//! *front* where o lies on the outer side of its plane. A segment from o
//! to a light point s crosses the closed surface an even number of times,
//! entering through a front triangle at least once if it crosses at all,
//! so s is hidden iff it lies in the shadow of some front triangle, and
//! the number of front triangles whose shadows hold s is the winding
//! number of their union's boundary: the silhouette edges (a front
//! triangle's edge whose other triangle is not front), projected from o
//! onto the light. Where those edges close one loop whose projection turns
//! one way once (a convex polygon), that winding is 1 inside the polygon
//! and 0 outside: the hidden samples are exactly the polygon's, the
//! intersection of one half-plane per silhouette edge (v_i, v_j), the
//! plane through o, v_i and v_j. Where they do not (two loops, a concave
//! outline: a solid convex at its edges but not as a whole, seen from
//! here), the triangles are marked one by one instead.
//!
//! The half-planes are computed as `cover::cover` computes a triangle's
//! edge planes (m = a_i x a_j in f64, an exact negation when the order
//! flips), so on the outline a sample is decided as the front triangle
//! there decides it; the polygon is marked row by row from the few edges
//! that cross each row (`polygon.rs`). A triangle nearly edge-on to o may be taken as front or not:
//! its shadow is a sliver along the outline, the grazing rays `tests.rs`
//! counts.

use super::cover::HalfPlane;
use glam::{DVec2, DVec3, Vec3};

/// A solid's topology: what its silhouette from an origin is found from
/// (corner ids; kept with the tree's shape, `pieces.rs`).
pub(crate) struct Solid {
    /// Each triangle's corners, as input.
    faces: Vec<[u32; 3]>,
    /// Each edge: its corners a -> b as triangle f winds them, and the
    /// triangle g that winds them b -> a.
    edges: Vec<[u32; 4]>,
}

/// A solid's triangles' outward planes n · x = d at one call's
/// coordinates (f32: they only sort the triangles into front and back; a
/// near tie is a sliver, see above), one array a coordinate.
pub(crate) struct Planes {
    nx: Vec<f32>,
    ny: Vec<f32>,
    nz: Vec<f32>,
    d: Vec<f32>,
}

/// A worker's buffers for `outline`.
#[derive(Default)]
pub(crate) struct Scratch {
    front: Vec<bool>,
    /// Per corner: the next corner along the silhouette (`NONE`: none yet).
    next: Vec<u32>,
    touched: Vec<u32>,
    ring: Vec<u32>,
    p: Vec<DVec2>,
    a: Vec<DVec3>,
    /// The half-planes `outline` leaves, and the rows each edge spans.
    pub planes: Vec<HalfPlane>,
    pub ys: Vec<[f32; 2]>,
    /// `polygon::mark_polygon`'s buffer.
    pub active: Vec<HalfPlane>,
}

const NONE: u32 = u32::MAX;

impl Solid {
    /// The solid of the triangles `faces` (corner ids into `corners`, as
    /// input), or None where they are not one: an edge not shared by
    /// exactly two triangles winding it opposite ways, a degenerate
    /// triangle, another topology than the sphere's, no volume, or an
    /// edge where the surface turns inward by more than a relative 1e-6.
    pub(crate) fn new(corners: &[Vec3], faces: &[[u32; 3]]) -> Option<Solid> {
        if faces
            .iter()
            .any(|f| f[0] == f[1] || f[1] == f[2] || f[2] == f[0])
        {
            return None;
        }
        // Directed edges, sorted by their undirected key: each key twice,
        // once each way.
        let mut dir: Vec<(u64, u32)> = Vec::with_capacity(3 * faces.len());
        for (k, f) in faces.iter().enumerate() {
            for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
                let key = u64::from(a.min(b)) << 33 | u64::from(a.max(b)) << 1 | u64::from(a > b);
                dir.push((key, k as u32));
            }
        }
        dir.sort_unstable();
        if !dir.len().is_multiple_of(2) {
            return None;
        }
        let mut edges = Vec::with_capacity(dir.len() / 2);
        for pair in dir.chunks_exact(2) {
            let ((k0, f0), (k1, f1)) = (pair[0], pair[1]);
            // The same edge, wound once each way (the low bit the way).
            if k0 >> 1 != k1 >> 1 || k0 & 1 != 0 || k1 & 1 != 1 {
                return None;
            }
            let (lo, hi) = ((k0 >> 33) as u32, ((k0 >> 1) & 0xffff_ffff) as u32);
            // f0 winds lo -> hi, f1 hi -> lo.
            edges.push([lo, hi, f0, f1]);
        }
        let used = {
            let mut seen = vec![false; corners.len()];
            faces
                .iter()
                .flatten()
                .for_each(|&c| seen[c as usize] = true);
            seen.iter().filter(|&&s| s).count()
        };
        if used as i64 - edges.len() as i64 + faces.len() as i64 != 2 {
            return None;
        }
        let v = |c: u32| corners[c as usize].as_dvec3();
        let normal = |f: &[u32; 3]| (v(f[1]) - v(f[0])).cross(v(f[2]) - v(f[0]));
        let out = orientation(corners, faces)?;
        let [lo, hi] = corners
            .iter()
            .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[l, h], &c| {
                [l.min(c), h.max(c)]
            });
        let size =
            f64::from((hi - lo).max_element()) + f64::from(lo.abs().max(hi.abs()).max_element());
        let far = |f: &[u32; 3], a: u32, b: u32| {
            f.iter().copied().find(|&c| c != a && c != b).unwrap_or(a)
        };
        for e in &edges {
            let [a, b, f, g] = *e;
            for (this, other) in [(f, g), (g, f)] {
                let t = &faces[this as usize];
                let n = normal(t) * out;
                let w = far(&faces[other as usize], a, b);
                if n.dot(v(w) - v(t[0])) > 1e-6 * n.length() * size {
                    return None;
                }
            }
        }
        Some(Solid {
            faces: faces.to_vec(),
            edges,
        })
    }

    /// Its triangles' outward planes at `corners` (this call's
    /// coordinates of its corners); None where it has no volume there.
    pub(crate) fn planes(&self, corners: &[Vec3]) -> Option<Planes> {
        let out = orientation(corners, &self.faces)?;
        let v = |c: u32| corners[c as usize].as_dvec3();
        let mut p = Planes {
            nx: Vec::with_capacity(self.faces.len()),
            ny: Vec::with_capacity(self.faces.len()),
            nz: Vec::with_capacity(self.faces.len()),
            d: Vec::with_capacity(self.faces.len()),
        };
        for f in &self.faces {
            let n = (v(f[1]) - v(f[0])).cross(v(f[2]) - v(f[0])) * out;
            p.nx.push(n.x as f32);
            p.ny.push(n.y as f32);
            p.nz.push(n.z as f32);
            p.d.push(n.dot(v(f[0])) as f32);
        }
        Some(p)
    }
}

/// The sign that turns the triangles `faces` outward: their signed
/// volume's; None where it is 0 or not finite.
fn orientation(corners: &[Vec3], faces: &[[u32; 3]]) -> Option<f64> {
    let v = |c: u32| corners[c as usize].as_dvec3();
    let volume: f64 = faces
        .iter()
        .map(|f| v(f[0]).dot(v(f[1]).cross(v(f[2]))))
        .sum();
    (volume.abs() > 0.0 && volume.is_finite()).then(|| volume.signum())
}

/// The samples the solid of `corners` hides from `o` (on `side`), as
/// the half-planes of one convex polygon left in `s.planes`; false where its triangles must be marked one
/// by one instead (a corner not between the light and o, a silhouette of
/// more than one loop or not convex, a degenerate outline).
#[allow(clippy::too_many_arguments)]
pub(crate) fn outline(
    (solid, planes): (&Solid, &Planes),
    corners: &[Vec3],
    bounds: [Vec3; 2],
    o: Vec3,
    t0: f32,
    t1: f32,
    side: Option<HalfPlane>,
    s: &mut Scratch,
) -> bool {
    s.planes.clear();
    // The depths `cover::cover` drops its end planes for, every corner.
    let margin = 1.0 + 1e-3;
    if !(bounds[0].z > (1.0 - t1) * o.z * margin && bounds[1].z * margin < (1.0 - t0) * o.z) {
        return false;
    }
    // Front: o on the outer side of the plane.
    let n = planes.d.len();
    s.front.clear();
    s.front.extend(
        (0..n).map(|k| planes.nx[k] * o.x + planes.ny[k] * o.y + planes.nz[k] * o.z > planes.d[k]),
    );
    // Every entry is NONE between calls (the ones set are reset below), so
    // the buffer only grows, to the largest solid's corners.
    if s.next.len() < corners.len() {
        s.next.resize(corners.len(), NONE);
    }
    // The silhouette edges, wound as their front triangle winds them.
    let mut count = 0usize;
    let mut first = NONE;
    let mut ok = true;
    for &[a, b, f, g] in &solid.edges {
        let (ff, fg) = (s.front[f as usize], s.front[g as usize]);
        if ff == fg {
            continue;
        }
        let (from, to) = if ff { (a, b) } else { (b, a) };
        if s.next[from as usize] != NONE {
            // Two silhouette edges leave one corner: not one simple loop.
            ok = false;
            break;
        }
        s.next[from as usize] = to;
        s.touched.push(from);
        count += 1;
        first = from;
    }
    // The loop from `first`, if it is one and holds every edge.
    s.ring.clear();
    if ok && count >= 3 {
        let mut c = first;
        while s.ring.len() <= count {
            s.ring.push(c);
            c = s.next[c as usize];
            if c == NONE || c == first {
                break;
            }
        }
        ok = c == first && s.ring.len() == count;
    } else {
        ok = false;
    }
    for &c in &s.touched {
        s.next[c as usize] = NONE;
    }
    s.touched.clear();
    ok && polygon(corners, o, side, s)
}

/// The half-planes of the convex polygon `s.ring` projected from `o`
/// (and `side`), left in `s.planes`; false where it is not one (it turns
/// both ways, or around more than once, or an edge is degenerate).
fn polygon(corners: &[Vec3], o: Vec3, side: Option<HalfPlane>, s: &mut Scratch) -> bool {
    let od = o.as_dvec3();
    s.a.clear();
    s.a.extend(s.ring.iter().map(|&c| corners[c as usize].as_dvec3() - od));
    s.p.clear();
    // The corners seen from o on z = 0: o - a o.z / a.z.
    s.p.extend(
        s.a.iter()
            .map(|a| od.truncate() - a.truncate() * (od.z / a.z)),
    );
    let (p, a) = (&s.p, &s.a);
    let m = p.len();
    // Convex: every turn one way (within a relative hair: corners along
    // one silhouette line), and one revolution: turning one way, the
    // edges' direction passes the +x axis once (from below it to above
    // it, counter-clockwise; the reverse, clockwise).
    let mut turn = 0.0f64;
    for i in 0..m {
        let (u, w) = (p[(i + 1) % m] - p[i], p[(i + 2) % m] - p[(i + 1) % m]);
        let cross = u.perp_dot(w);
        if !cross.is_finite() {
            return false;
        }
        if cross.abs() > 1e-9 * u.length() * w.length() {
            if turn == 0.0 {
                turn = cross.signum();
            } else if cross.signum() != turn {
                return false;
            }
        }
    }
    let passes = (0..m)
        .filter(|&i| {
            let (u, w) = (p[(i + 1) % m] - p[i], p[(i + 2) % m] - p[(i + 1) % m]);
            if turn > 0.0 {
                u.y < 0.0 && w.y >= 0.0
            } else {
                u.y >= 0.0 && w.y < 0.0
            }
        })
        .count();
    if turn == 0.0 || passes != 1 {
        return false;
    }
    let mid = p.iter().sum::<DVec2>() / m as f64;
    s.planes.clear();
    s.ys.clear();
    for i in 0..m {
        let j = (i + 1) % m;
        let e = a[i].cross(a[j]);
        // m · d at the outline's centre (d = s - o), its sign the inside's.
        let inside = e.x * (mid.x - od.x) + e.y * (mid.y - od.y) - e.z * od.z;
        if !(inside.abs() > 0.0) || !inside.is_finite() {
            return false;
        }
        let k = inside.signum();
        s.planes.push(HalfPlane {
            a: (k * (-e.dot(od))) as f32,
            b: (k * e.x) as f32,
            c: (k * e.y) as f32,
            strict: false,
        });
        // The rows its corners span, widened by a relative hair over the
        // rounding of the projection and of the f32.
        let (ya, yb) = (p[i].y.min(p[j].y), p[i].y.max(p[j].y));
        let pad = 1e-4 * (1.0 + ya.abs().max(yb.abs()));
        s.ys.push([(ya - pad) as f32, (yb + pad) as f32]);
    }
    if let Some(sd) = side {
        s.planes.push(sd);
        s.ys.push([f32::NEG_INFINITY, f32::INFINITY]);
    }
    true
}
