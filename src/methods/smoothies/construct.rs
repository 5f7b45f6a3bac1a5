//! Step 3 of Chan & Durand 2003 (§3, Fig. 2, Fig. 6): smoothie edges and
//! smoothie corners, built in the light's image plane.
//!
//! The image plane. Tangent coordinates scaled by the light's full size,
//! q = (x / Lu, y / Lv): there the light is a unit square, so one width t
//! serves both axes. An edge at depth b seen from a receiver at depth r has an
//! outer penumbra of (1/2)(1/b - 1/r) in q units (half the light is 1/2), and
//! the published remap alpha' = alpha / (1 - b/r) of a smoothie of width
//! t = 1/(2b) reproduces it. So, for the user's dimensionless `width`,
//!     t = width / (2 b_ref),   b_ref = median depth of the silhouette edges' midpoints,
//! i.e. width (Lu/2) / b_ref tangent units across u and width (Lv/2) / b_ref across v.
//!
//! Smoothie edge: the projected silhouette edge p0 -> p1 extended outward (to
//! its left, see silhouette.rs) by t: a texel centre q with s = (q - p0).d / |p1 - p0|
//! in [0, 1] and h = (q - p0).n in (0, t) gets alpha = h / t and the depth of
//! the edge point at s, 1/b = (1 - s)/z0 + s/z1 (the exact planar depth of the
//! 3D edge point projecting there: 1/z is linear along a projected segment).
//!
//! Smoothie corner, at a silhouette vertex v with one incoming edge A and one
//! outgoing edge B that turns toward the blocker (cross(dA, dB) <= 0): the gap
//! left between the two rectangles, {q : (q - v).dA > 0, (q - v).dB < 0},
//! gets alpha = |q - v| / t, clamped (so only the disc of radius t matters:
//! the paper's corner quad with its alpha clamped to 1). At a reflex vertex
//! the rectangles overlap and there is no gap.
//!
//! Special case (§3): a vertex with more than two adjacent silhouette edges
//! (or two that do not chain head to tail): the mean m of the edges' outward
//! normals, scaled to length t (the paper averages the adjacent face normals;
//! the image-plane normals of the edges are their projection's analogue), and
//! one triangle (v, v + t n_k, v + m) per adjacent edge k, alpha = |q - v| / t
//! clamped. A vertex with one silhouette edge (a clipped or open chain) gets
//! no corner.
//!
//! Clipping: each edge is clipped in 3D to the map's frustum widened by t and
//! two texels, and to z >= z_min > 0, so nothing behind the light plane is
//! projected and every smoothie lies within a bounded distance of the grid.
//! Corners are built only at endpoints that were not clipped.

use super::silhouette::Silhouette;
use crate::geom::light::MapGrid;
use glam::{DVec2, DVec3};

/// One smoothie primitive in q space.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Shape {
    Edge {
        p0: DVec2,
        /// Unit direction p0 -> p1, its length, the outward unit normal.
        d: DVec2,
        len: f64,
        n: DVec2,
        inv_z0: f64,
        inv_z1: f64,
    },
    Corner {
        v: DVec2,
        z: f64,
        da: DVec2,
        db: DVec2,
    },
    Fan {
        v: DVec2,
        z: f64,
        o: DVec2,
        m: DVec2,
    },
}

/// The smoothies of a silhouette and the number of corners among them.
#[derive(Debug, Clone, Default)]
pub(super) struct Smoothies {
    pub shapes: Vec<Shape>,
    pub corners: usize,
}

/// The parameter range [s0, s1] of segment a + s (b - a) where g >= 0, for
/// linear g given by its values at a and b.
fn clip_range(range: (f64, f64), ga: f64, gb: f64) -> Option<(f64, f64)> {
    let (mut s0, mut s1) = range;
    if ga < 0.0 && gb < 0.0 {
        return None;
    }
    if ga < 0.0 {
        s0 = s0.max(ga / (ga - gb));
    } else if gb < 0.0 {
        s1 = s1.min(ga / (ga - gb));
    }
    (s0 <= s1).then_some((s0, s1))
}

/// Clips segment ab to z >= zmin and |x| <= xm z, |y| <= ym z.
fn clip_segment(a: DVec3, b: DVec3, zmin: f64, xm: f64, ym: f64) -> Option<(f64, f64)> {
    let planes: [&dyn Fn(DVec3) -> f64; 5] = [
        &|p| p.z - zmin,
        &|p| xm * p.z - p.x,
        &|p| xm * p.z + p.x,
        &|p| ym * p.z - p.y,
        &|p| ym * p.z + p.y,
    ];
    let mut r = (0.0, 1.0);
    for g in planes {
        r = clip_range(r, g(a), g(b))?;
    }
    Some(r)
}

fn perp_left(d: DVec2) -> DVec2 {
    DVec2::new(-d.y, d.x)
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The nearest depth that is projected: relative to the farthest vertex.
fn z_min(sil: &Silhouette) -> f64 {
    let zmax = sil
        .points
        .iter()
        .map(|p| p.z)
        .filter(|z| z.is_finite() && *z > 0.0)
        .fold(0.0, f64::max);
    (zmax * 1e-9).max(f64::MIN_POSITIVE)
}

/// b_ref: the median planar depth of the silhouette edges' midpoints (the
/// part of each edge in front of the light plane); None without any.
pub(super) fn reference_depth(sil: &Silhouette) -> Option<f64> {
    let zmin = z_min(sil);
    let mut mids: Vec<f64> = sil
        .edges
        .iter()
        .filter_map(|e| {
            let (a, b) = (sil.points[e.a as usize], sil.points[e.b as usize]);
            let (s0, s1) = clip_range((0.0, 1.0), a.z - zmin, b.z - zmin)?;
            let z = a.z + (b.z - a.z) * (0.5 * (s0 + s1));
            (z.is_finite() && z > 0.0).then_some(z)
        })
        .collect();
    if mids.is_empty() {
        return None;
    }
    let mid = mids.len() / 2;
    let (_, m, _) = mids.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// Builds the smoothie edges and corners of `sil` for width `t` (q units).
pub(super) fn build(sil: &Silhouette, grid: &MapGrid, light: [f64; 2], t: f64) -> Smoothies {
    let mut out = Smoothies::default();
    if !(t > 0.0 && t.is_finite()) {
        return out;
    }
    let zmin = z_min(sil);
    let (hx, hy) = grid.half_texel();
    let xm = grid.tx + t * light[0] + 4.0 * hx;
    let ym = grid.ty + t * light[1] + 4.0 * hy;
    let q_of = |p: DVec3| DVec2::new(p.x / (p.z * light[0]), p.y / (p.z * light[1]));
    // Per vertex: (vertex, edge shape index, incoming).
    let mut ends: Vec<(u32, u32, bool)> = Vec::new();
    for e in &sil.edges {
        let (a, b) = (sil.points[e.a as usize], sil.points[e.b as usize]);
        let Some((s0, s1)) = clip_segment(a, b, zmin, xm, ym) else {
            continue;
        };
        let (pa, pb) = (a + (b - a) * s0, a + (b - a) * s1);
        let (q0, q1) = (q_of(pa), q_of(pb));
        let dq = q1 - q0;
        let len = dq.length();
        if !(len > 1e-9 * t && len.is_finite() && q0.is_finite() && q1.is_finite()) {
            continue; // an edge seen end-on: no extent in the image plane
        }
        let d = dq / len;
        let idx = out.shapes.len() as u32;
        out.shapes.push(Shape::Edge {
            p0: q0,
            d,
            len,
            n: perp_left(d),
            inv_z0: 1.0 / pa.z,
            inv_z1: 1.0 / pb.z,
        });
        if s0 == 0.0 {
            ends.push((e.a, idx, false));
        }
        if s1 == 1.0 {
            ends.push((e.b, idx, true));
        }
    }
    ends.sort_unstable();
    let edge_of = |i: u32| match out.shapes[i as usize] {
        Shape::Edge { d, n, .. } => (d, n),
        _ => unreachable!("ends index edges"),
    };
    let mut corners = Vec::new();
    for group in ends.chunk_by(|x, y| x.0 == y.0) {
        if group.len() < 2 {
            continue;
        }
        let p = sil.points[group[0].0 as usize];
        let (v, z) = (q_of(p), p.z);
        let incoming: Vec<_> = group.iter().filter(|g| g.2).collect();
        if group.len() == 2 && incoming.len() == 1 {
            let (a, b) = if group[0].2 {
                (group[0].1, group[1].1)
            } else {
                (group[1].1, group[0].1)
            };
            let ((da, _), (db, _)) = (edge_of(a), edge_of(b));
            if cross(da, db) <= 0.0 && da.dot(db) < 1.0 - 1e-12 {
                corners.push(Shape::Corner { v, z, da, db });
                out.corners += 1;
            }
            continue;
        }
        let sum: DVec2 = group.iter().map(|g| edge_of(g.1).1).sum();
        if !(sum.length() > 1e-9) {
            continue;
        }
        let m = v + sum.normalize() * t;
        for g in group {
            let o = v + edge_of(g.1).1 * t;
            corners.push(Shape::Fan { v, z, o, m });
        }
        out.corners += 1;
    }
    out.shapes.extend(corners);
    out
}

impl Shape {
    /// The convex polygon (q space) that holds the shape's texels.
    pub(crate) fn hull(&self, t: f64) -> ([DVec2; 4], usize) {
        match *self {
            Shape::Edge { p0, d, len, n, .. } => {
                let p1 = p0 + d * len;
                ([p0, p1, p1 + n * t, p0 + n * t], 4)
            }
            Shape::Corner { v, .. } => {
                let (a, b) = (DVec2::new(t, t), DVec2::new(t, -t));
                ([v - a, v - b, v + a, v + b], 4)
            }
            Shape::Fan { v, o, m, .. } => ([v, o, m, m], 3),
        }
    }

    /// The linear alpha in (0, 1) and depth at texel centre q, or None
    /// outside the smoothie (or where alpha is 1: no shadow).
    #[inline]
    pub(super) fn sample(&self, q: DVec2, t: f64) -> Option<(f64, f64)> {
        match *self {
            Shape::Edge {
                p0,
                d,
                len,
                n,
                inv_z0,
                inv_z1,
            } => {
                let w = q - p0;
                let s = w.dot(d) / len;
                let h = w.dot(n);
                if !((0.0..=1.0).contains(&s) && h > 0.0 && h < t) {
                    return None;
                }
                Some((h / t, 1.0 / ((1.0 - s) * inv_z0 + s * inv_z1)))
            }
            Shape::Corner { v, z, da, db } => {
                let w = q - v;
                if !(w.dot(da) > 0.0 && w.dot(db) < 0.0) {
                    return None;
                }
                let r = w.length();
                (r < t).then_some((r / t, z))
            }
            Shape::Fan { v, z, o, m } => {
                let w = q - v;
                let r = w.length();
                if !(r > 0.0 && r < t) {
                    return None;
                }
                let (c0, c1, c2) = (
                    cross(o - v, q - v),
                    cross(m - o, q - o),
                    cross(v - m, q - m),
                );
                let inside =
                    (c0 >= 0.0 && c1 >= 0.0 && c2 >= 0.0) || (c0 <= 0.0 && c1 <= 0.0 && c2 <= 0.0);
                inside.then_some((r / t, z))
            }
        }
    }
}
