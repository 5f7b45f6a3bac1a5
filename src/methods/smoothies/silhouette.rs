//! Step 2 of Chan & Durand 2003 (§3): silhouette edges with respect to the
//! light's centre, found in object space from the mesh's adjacency.
//!
//! Maths. A face (a, b, c) with normal n = (b - a) x (c - a) faces the light
//! (at the origin) when n . (0 - a) > 0. Since n . a = det(a, b, c) and the
//! projection onto the tangent plane (x/z, y/z) scales det by 1/(za zb zc),
//! a front-facing face with z > 0 projects *clockwise* (x right, y up): its
//! interior lies to the right of each of its edges taken in winding order.
//!
//! Rules (the paper assumes closed meshes; ours may be anything):
//! * Vertices are welded by exact position (so split-vertex meshes, e.g. a
//!   cube with 24 vertices, have their adjacency); non-finite vertices, faces
//!   with an index out of range, repeated (welded) vertices or a zero-area
//!   cross product are ignored.
//! * Each face is Front (n . (0 - a) > eps), Back (< -eps) or EdgeOn.
//! * An edge whose faces include a Front and a non-Front face is a silhouette
//!   (a manifold edge between a front- and a back-facing face; for a
//!   non-manifold edge, 3+ faces, the same rule: both orientations present).
//! * A boundary edge (one face) is a silhouette unless its face is EdgeOn
//!   (it projects to a line and casts no area).
//! * Outward (away from the blocker in the image plane) is to the LEFT of the
//!   edge as returned: the edge is directed as in the winding of its first
//!   Front face (interior on the right), or against the winding of a lone
//!   Back face. On a consistently wound mesh the edges then chain head to
//!   tail around each silhouette loop, blocker on the right.

use glam::DVec3;

/// A silhouette edge between welded vertices `a` -> `b`: the blocker lies to
/// the right of it in the light's image plane, outward is to the left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct SilEdge {
    pub a: u32,
    pub b: u32,
}

/// The welded vertex positions and the silhouette edges over them.
#[derive(Debug, Clone, Default)]
pub(super) struct Silhouette {
    pub points: Vec<DVec3>,
    pub edges: Vec<SilEdge>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Facing {
    Front,
    Back,
    EdgeOn,
}

/// One face's use of an edge: (lo, hi) welded ids, whether the face's winding
/// runs lo -> hi, the face's orientation, and the face index (for a
/// deterministic order).
type Use = (u32, u32, Facing, bool, u32);

fn weld(verts: &[DVec3]) -> (Vec<DVec3>, Vec<Option<u32>>) {
    use std::collections::HashMap;
    let mut ids: HashMap<[u64; 3], u32> = HashMap::with_capacity(verts.len());
    let mut points = Vec::new();
    let map = verts
        .iter()
        .map(|p| {
            if !p.is_finite() {
                return None;
            }
            // +0.0 for -0.0, so the two weld.
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            Some(*ids.entry(key).or_insert_with(|| {
                points.push(*p);
                (points.len() - 1) as u32
            }))
        })
        .collect();
    (points, map)
}

fn facing(a: DVec3, b: DVec3, c: DVec3) -> Option<Facing> {
    let (e1, e2) = (b - a, c - a);
    let n = e1.cross(e2);
    let scale = e1.length_squared().max(e2.length_squared());
    let nl = n.length();
    if !(nl > 1e-12 * scale) || !nl.is_finite() {
        return None; // degenerate (collinear or repeated points)
    }
    let s = -n.dot(a);
    let eps = 1e-12 * nl * a.length().max(b.length()).max(c.length());
    Some(if s > eps {
        Facing::Front
    } else if s < -eps {
        Facing::Back
    } else {
        Facing::EdgeOn
    })
}

/// The silhouette of the occluder mesh(es) seen from the light's centre.
pub(super) fn silhouette(verts: &[DVec3], faces: &[[u32; 3]]) -> Silhouette {
    let (points, map) = weld(verts);
    let mut uses: Vec<Use> = Vec::with_capacity(faces.len() * 3);
    for (fi, f) in faces.iter().enumerate() {
        let ids = f.map(|i| map.get(i as usize).copied().flatten());
        let [Some(i0), Some(i1), Some(i2)] = ids else {
            continue;
        };
        if i0 == i1 || i1 == i2 || i0 == i2 {
            continue;
        }
        let Some(fc) = facing(
            points[i0 as usize],
            points[i1 as usize],
            points[i2 as usize],
        ) else {
            continue;
        };
        for (s, e) in [(i0, i1), (i1, i2), (i2, i0)] {
            uses.push((s.min(e), s.max(e), fc, s < e, fi as u32));
        }
    }
    uses.sort_unstable();
    let mut edges = Vec::new();
    let mut k = 0;
    while k < uses.len() {
        let (lo, hi) = (uses[k].0, uses[k].1);
        let mut end = k;
        while end < uses.len() && uses[end].0 == lo && uses[end].1 == hi {
            end += 1;
        }
        let group = &uses[k..end];
        k = end;
        // Sorted by facing: a Front use, if any, comes first.
        let first = group[0];
        let directed = |forward: bool| {
            if forward {
                SilEdge { a: lo, b: hi }
            } else {
                SilEdge { a: hi, b: lo }
            }
        };
        if group.len() == 1 {
            match first.2 {
                Facing::Front => edges.push(directed(first.3)),
                Facing::Back => edges.push(directed(!first.3)),
                Facing::EdgeOn => {}
            }
        } else if first.2 == Facing::Front && group.iter().any(|u| u.2 != Facing::Front) {
            edges.push(directed(first.3));
        }
    }
    Silhouette { points, edges }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_front_face_is_clockwise_in_the_image_plane() {
        // Normal toward the light (-z): (b - a) x (c - a) = (0, 0, -1).
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
        );
        assert_eq!(facing(a, b, c), Some(Facing::Front));
        // Projected (0,0) -> (0,.5) -> (.5,0) turns clockwise.
        let s = silhouette(&[a, b, c], &[[0, 1, 2]]);
        assert_eq!(s.edges.len(), 3);
        // The edge 0 -> 1 runs up the y axis; the face is on its right (+x).
        assert!(s.edges.contains(&SilEdge { a: 0, b: 1 }));
        // The same face wound the other way is Back, its edges reversed: the same set.
        let s2 = silhouette(&[a, b, c], &[[0, 2, 1]]);
        assert_eq!(s2.edges.len(), 3);
        assert!(s2.edges.contains(&SilEdge { a: 0, b: 1 }));
    }
}
