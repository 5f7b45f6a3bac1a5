//! Closed convex pieces (a box, a slat, a wall, a tetrahedron): each one's
//! shadow on the light is one convex polygon, the outline of its corners
//! seen from the origin, instead of the union of its triangles' shadows.
//!
//! A piece P is a run of consecutive input triangles (a mesh of its own,
//! or one part of a multi-part mesh) that is closed (every edge, corners
//! matched bit for bit, is shared by exactly two of its triangles) and
//! convex (every corner lies on one side of each triangle's plane, within
//! a relative 1e-6). Its surface is then the boundary of the convex hull
//! of its corners, so a segment from an origin o outside it crosses one of
//! its triangles iff its direction lies in the cone from o over the hull.
//! Where every corner lies deeper than the light and shallower than o by
//! the same margins `cover::cover` uses to drop its end planes, every such
//! crossing has t in (t0, t1) and o is outside P (a point inside the hull
//! of corners would have one as deep as itself), so the samples P hides
//! are exactly those inside the 2D convex hull of its corners projected
//! from o onto the light (z = 0): one half-plane per hull edge (v_i, v_j),
//! the plane through o, v_i and v_j.
//!
//! Those half-planes are computed as `cover::cover` computes a triangle's
//! edge planes (m = a_i x a_j, a = v - o in f64, an exact negation when
//! the order flips), so where the hull edge is a triangle's edge, its bits
//! are that triangle's: a sample on the outline is decided as the
//! triangle decides it. A hull edge that is no mesh edge (corners in a
//! line) bounds the same cone within rounding. Where the conditions fail
//! (a corner behind the origin or beyond the light, a hull of more edges
//! than a cover holds, a degenerate outline), the piece's triangles are
//! marked one by one instead, as every other triangle is.
//!
//! Why: a thin closed box seen across the light (a slat, a shelf, a wall)
//! is twelve triangles whose shadows overlap along the same outline, and
//! each one's edges cross the same cells of the pattern: the outline costs
//! the cells its six edges cross, once.

use super::cover::{Cover, HalfPlane, PLANES};
use super::solids::{Planes, Solid};
use crate::trace::bvh::Bvh;
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// Corners a piece holds at most (a box has 8).
const MAX_CORNERS: usize = 16;
/// Triangles a piece holds at most: a closed surface of V corners has
/// 2V - 4 triangles.
const MAX_TRIANGLES: usize = 2 * MAX_CORNERS - 4;
/// A piece's corners, as (triangle slot, corner) of a use of each.
type Refs = Vec<(u32, u8)>;
/// No piece: a triangle marked on its own.
pub(crate) const NONE: u32 = u32::MAX;
/// Triangles a solid (`solids.rs`) holds at most: its silhouette is found
/// by a pass over its triangles and edges, once per origin that meets it.
const MAX_SOLID: usize = 1 << 16;

/// Which runs of a tree's triangles are pieces and solids: what their
/// input order and corners' bits decide, found once a tree's shape
/// (`Bvh::derived`: a prepared scene's calls, refitted, reuse it).
pub(crate) struct Shapes {
    /// The piece of each triangle, in the tree's order (`NONE`: none).
    of: Vec<u32>,
    /// Per node of the tree: the piece every triangle under it belongs
    /// to, else `NONE` (a traversal meeting an outlined piece's node skips
    /// it whole: a solid's thousands of triangles cost one box test).
    node: Vec<u32>,
    /// Piece k's corners, as (triangle slot, corner) of their first use:
    /// `refs[refs_start[k]..refs_start[k + 1]]`.
    refs_start: Vec<u32>,
    refs: Vec<(u32, u8)>,
    /// Piece k's triangles (slots), for the convexity a small piece is
    /// tested for again at each call's coordinates.
    slots_start: Vec<u32>,
    slots: Vec<u32>,
    /// Each piece's topology where it is a solid (`solids.rs`: more
    /// triangles than a hull of its corners is worth), None where it is
    /// outlined by that hull.
    solids: Vec<Option<Solid>>,
}

/// The pieces at one call's coordinates.
pub(crate) struct Pieces {
    shapes: Arc<Shapes>,
    /// Piece k's corners are `corners[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    corners: Vec<Vec3>,
    /// Each piece's box.
    pub bounds: Vec<[Vec3; 2]>,
    /// Whether piece k is outlined at these coordinates (a small piece
    /// still convex, a solid with a volume; else its triangles are
    /// marked), and a solid's planes.
    live: Vec<bool>,
    planes: Vec<Option<Planes>>,
}

impl Pieces {
    /// The pieces of `bvh`'s triangles: their shapes (found once a tree's
    /// shape), at the tree's coordinates.
    pub(crate) fn find(bvh: &Bvh) -> Pieces {
        let shapes = bvh.derived(|| Shapes::find(bvh));
        let tris = bvh.triangles();
        let n = shapes.solids.len();
        let at = |&(s, c): &(u32, u8)| tris[s as usize][c as usize];
        let corners: Vec<Vec3> = shapes.refs.iter().map(at).collect();
        let start = shapes.refs_start.clone();
        let of_piece = |k: usize| &corners[start[k] as usize..start[k + 1] as usize];
        let bounds: Vec<[Vec3; 2]> = (0..n).map(|k| bounds(of_piece(k))).collect();
        let per: Vec<(bool, Option<Planes>)> = (0..n)
            .into_par_iter()
            .with_min_len(64)
            .map(|k| match &shapes.solids[k] {
                Some(solid) => {
                    let p = solid.planes(of_piece(k));
                    (p.is_some(), p)
                }
                None => {
                    let slots = &shapes.slots
                        [shapes.slots_start[k] as usize..shapes.slots_start[k + 1] as usize];
                    (convex(tris, slots, of_piece(k)), None)
                }
            })
            .collect();
        let (live, planes) = per.into_iter().unzip();
        Pieces {
            shapes,
            start,
            corners,
            bounds,
            live,
            planes,
        }
    }

    /// The piece of each triangle, in the tree's order (`NONE`: none).
    #[inline(always)]
    pub(crate) fn of(&self) -> &[u32] {
        &self.shapes.of
    }

    /// Per node: the piece every triangle under it belongs to, or `NONE`.
    #[inline(always)]
    pub(crate) fn node(&self) -> &[u32] {
        &self.shapes.node
    }

    /// Whether piece k is outlined at these coordinates.
    #[inline(always)]
    pub(crate) fn live(&self, k: u32) -> bool {
        self.live[k as usize]
    }

    /// Piece k's topology and planes, where it is a solid.
    #[inline(always)]
    pub(crate) fn solid(&self, k: u32) -> Option<(&Solid, &Planes)> {
        let k = k as usize;
        self.shapes.solids[k].as_ref().zip(self.planes[k].as_ref())
    }

    /// How many of the pieces are solids.
    #[cfg(test)]
    pub(crate) fn solids(&self) -> usize {
        self.shapes.solids.iter().filter(|s| s.is_some()).count()
    }

    pub(crate) fn len(&self) -> usize {
        self.bounds.len()
    }

    /// Piece k's corners.
    #[inline(always)]
    pub(crate) fn corners(&self, k: u32) -> &[Vec3] {
        &self.corners[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

impl Shapes {
    /// The pieces and solids of `bvh`'s triangles, found in their input
    /// order.
    fn find(bvh: &Bvh) -> Shapes {
        let tris = bvh.triangles();
        let order = bvh.order();
        let mut slot = vec![0u32; tris.len()];
        for (s, &i) in order.iter().enumerate() {
            slot[i as usize] = s as u32;
        }
        let mut p = Shapes {
            of: vec![NONE; tris.len()],
            node: vec![],
            refs_start: vec![0],
            refs: vec![],
            slots_start: vec![0],
            slots: vec![],
            solids: vec![],
        };
        // A closed run has every edge twice, so its edges' hashes XOR to
        // zero: the runs i..j worth the exact test have equal prefix XORs
        // at i and j (one pass of hashes; a big mesh has almost none).
        let xor: Vec<u64> = slot
            .par_iter()
            .map(|&s| edge_xor(&tris[s as usize]))
            .collect();
        let mut prefix = Vec::with_capacity(xor.len() + 1);
        prefix.push(0u64);
        for (k, x) in xor.iter().enumerate() {
            prefix.push(prefix[k] ^ x);
        }
        let n = tris.len();
        let starts: Vec<usize> = (0..n)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&i| {
                i + 4 <= n && prefix[i + 4..=(i + MAX_TRIANGLES).min(n)].contains(&prefix[i])
            })
            .collect();
        let mut next = 0;
        for i in starts {
            if i < next {
                continue;
            }
            match closed_run(tris, &slot, i) {
                Some((end, corners, refs)) if convex(tris, &slot[i..end], &corners) => {
                    p.push(&slot[i..end], &refs, None);
                    next = end;
                }
                _ => {}
            }
        }
        p.find_solids(tris, &slot, &prefix);
        p.node = node_pieces(bvh, &p.of);
        p
    }

    /// Adds the piece of the triangles `slots`, its corners `refs`.
    fn push(&mut self, slots: &[u32], refs: &[(u32, u8)], solid: Option<Solid>) {
        let k = self.solids.len() as u32;
        for &s in slots {
            self.of[s as usize] = k;
        }
        self.refs.extend_from_slice(refs);
        self.refs_start.push(self.refs.len() as u32);
        if solid.is_none() {
            self.slots.extend_from_slice(slots);
        }
        self.slots_start.push(self.slots.len() as u32);
        self.solids.push(solid);
    }

    /// The solids: runs i..j longer than a piece, no triangle of them in
    /// one, with equal prefix XORs at i and j (j the next index holding
    /// i's), each tested as `Solid::new` says after a sample of its
    /// corners and planes (`likely_convex`: a bunny or a person fails it
    /// in a few hundred products, before the sort). The tests run in
    /// parallel; overlapping runs keep the first.
    fn find_solids(&mut self, tris: &[[Vec3; 3]], slot: &[u32], prefix: &[u64]) {
        let n = tris.len();
        let next = next_equal(prefix);
        let free = |i: usize, j: usize| slot[i..j].iter().all(|&s| self.of[s as usize] == NONE);
        let candidates: Vec<(usize, usize)> = (0..n)
            .filter_map(|i| {
                let j = next[i] as usize;
                (next[i] != NONE && j - i > MAX_TRIANGLES && j - i <= MAX_SOLID).then_some((i, j))
            })
            .filter(|&(i, j)| free(i, j))
            .collect();
        // A bound on the work: a scene's triangles, four times over.
        let mut work = 0usize;
        let candidates: Vec<(usize, usize)> = candidates
            .into_iter()
            .take_while(|&(i, j)| {
                work += j - i;
                work <= 4 * n
            })
            .collect();
        let found: Vec<Option<(Refs, Solid)>> = candidates
            .par_iter()
            .map(|&(i, j)| {
                let run = &slot[i..j];
                likely_convex(tris, run)
                    .then(|| solid_run(tris, run))
                    .flatten()
            })
            .collect();
        let mut end = 0;
        for (&(i, j), f) in candidates.iter().zip(found) {
            let Some((refs, solid)) = f else { continue };
            if i < end {
                continue;
            }
            self.push(&slot[i..j], &refs, Some(solid));
            end = j;
        }
    }
}

/// Per node of `bvh`: the piece of every triangle under it (`of`), else
/// `NONE`. Children follow their parent in the list (`bvh.rs`), so one
/// pass from the end sees them first.
fn node_pieces(bvh: &Bvh, of: &[u32]) -> Vec<u32> {
    let nodes = &bvh.nodes;
    let mut node = vec![NONE; nodes.len()];
    if bvh.is_empty() {
        return node;
    }
    for k in (0..nodes.len()).rev() {
        let n = &nodes[k];
        node[k] = if n.count > 0 {
            let leaf = &of[n.start as usize..(n.start + n.count) as usize];
            if leaf.iter().all(|&p| p == leaf[0]) {
                leaf[0]
            } else {
                NONE
            }
        } else {
            let (a, b) = (node[n.start as usize], node[n.start as usize + 1]);
            if a == b {
                a
            } else {
                NONE
            }
        };
    }
    node
}

/// For each i, the least j > i with `prefix[j] == prefix[i]` (`NONE`:
/// none): a table keyed by the values (already hashes), filled from the
/// end.
fn next_equal(prefix: &[u64]) -> Vec<u32> {
    let size = (2 * prefix.len()).next_power_of_two().max(16);
    let mask = size - 1;
    let (mut keys, mut at) = (vec![0u64; size], vec![NONE; size]);
    let mut next = vec![NONE; prefix.len()];
    for j in (0..prefix.len()).rev() {
        let key = prefix[j];
        let mut h = ((key ^ key >> 31).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 20) as usize & mask;
        loop {
            if at[h] == NONE {
                keys[h] = key;
                at[h] = j as u32;
                break;
            }
            if keys[h] == key {
                next[j] = at[h];
                at[h] = j as u32;
                break;
            }
            h = (h + 1) & mask;
        }
    }
    next
}

/// Whether 64 corners of the triangles `slots`, spread over them, lie on
/// one side of 16 of their planes (within `convex`'s tolerance): what a
/// convex surface passes and most others fail.
fn likely_convex(tris: &[[Vec3; 3]], slots: &[u32]) -> bool {
    let n = slots.len();
    let corners: Vec<Vec3> = (0..64)
        .map(|k| tris[slots[k * n / 64] as usize][k % 3])
        .collect();
    let faces: Vec<u32> = (0..16).map(|k| slots[(k * n / 16 + n / 32) % n]).collect();
    convex(tris, &faces, &corners)
}

/// The solid of the triangles `slots` (input order), with its corners as
/// (slot, corner) of their first use.
fn solid_run(tris: &[[Vec3; 3]], slots: &[u32]) -> Option<(Refs, Solid)> {
    // Corners matched bit for bit: their keys sorted, one id a key.
    let mut keys: Vec<([u32; 3], u32)> = Vec::with_capacity(3 * slots.len());
    for (f, &s) in slots.iter().enumerate() {
        for (c, v) in tris[s as usize].iter().enumerate() {
            keys.push((
                [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()],
                (3 * f + c) as u32,
            ));
        }
    }
    keys.sort_unstable();
    let mut faces = vec![[0u32; 3]; slots.len()];
    let mut corners = Vec::new();
    let mut refs = Vec::new();
    for (k, &(key, r)) in keys.iter().enumerate() {
        if k == 0 || keys[k - 1].0 != key {
            corners.push(Vec3::new(
                f32::from_bits(key[0]),
                f32::from_bits(key[1]),
                f32::from_bits(key[2]),
            ));
            refs.push((slots[r as usize / 3], (r % 3) as u8));
        }
        faces[r as usize / 3][r as usize % 3] = (corners.len() - 1) as u32;
    }
    let solid = Solid::new(&corners, &faces)?;
    Some((refs, solid))
}

/// The box of `corners`.
fn bounds(corners: &[Vec3]) -> [Vec3; 2] {
    corners
        .iter()
        .fold([Vec3::INFINITY, Vec3::NEG_INFINITY], |[lo, hi], &v| {
            [lo.min(v), hi.max(v)]
        })
}

/// A corner's hash, from its bits (a multiply and a shift: enough to
/// make unrelated edges' XOR vanish rarely; a false candidate only costs
/// the exact test).
#[inline(always)]
fn corner_hash(v: Vec3) -> u64 {
    let xy = u64::from(v.x.to_bits()) | u64::from(v.y.to_bits()) << 32;
    let h = xy.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ u64::from(v.z.to_bits()).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    h ^ h >> 29
}

/// The XOR of a triangle's three undirected edges' hashes (an edge's is
/// the product of its corners': symmetric, and not linear in XOR).
#[inline(always)]
fn edge_xor(t: &[Vec3; 3]) -> u64 {
    let h = t.map(corner_hash);
    h[0].wrapping_mul(h[1]) ^ h[1].wrapping_mul(h[2]) ^ h[2].wrapping_mul(h[0])
}

/// The triangles i..end (input order) where they close a surface of at
/// most `MAX_CORNERS` corners first, and its corners; None where they do
/// not (a corner too many, an edge shared by three).
fn closed_run(tris: &[[Vec3; 3]], slot: &[u32], i: usize) -> Option<(usize, Vec<Vec3>, Refs)> {
    let mut corners: Vec<[u32; 3]> = Vec::with_capacity(MAX_CORNERS);
    let mut at: Vec<Vec3> = Vec::with_capacity(MAX_CORNERS);
    let mut refs: Refs = Vec::with_capacity(MAX_CORNERS);
    // Undirected edges (corner ids, low first) and how many triangles use each.
    let mut edges: Vec<([u8; 2], u8)> = Vec::with_capacity(3 * MAX_CORNERS);
    let mut open = 0usize;
    for j in i..(i + MAX_TRIANGLES).min(tris.len()) {
        let t = &tris[slot[j] as usize];
        let mut id = [0u8; 3];
        for (c, v) in t.iter().enumerate() {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            id[c] = match corners.iter().position(|k| *k == key) {
                Some(k) => k as u8,
                None if corners.len() < MAX_CORNERS => {
                    corners.push(key);
                    at.push(*v);
                    refs.push((slot[j], c as u8));
                    (corners.len() - 1) as u8
                }
                None => return None,
            };
        }
        if id[0] == id[1] || id[1] == id[2] || id[2] == id[0] {
            return None;
        }
        for (a, b) in [(id[0], id[1]), (id[1], id[2]), (id[2], id[0])] {
            let e = [a.min(b), a.max(b)];
            match edges.iter_mut().find(|(k, _)| *k == e) {
                Some((_, n)) if *n == 1 => {
                    *n = 2;
                    open -= 1;
                }
                Some(_) => return None,
                None => {
                    edges.push((e, 1));
                    open += 1;
                }
            }
        }
        if open == 0 {
            return (j + 1 - i >= 4).then_some((j + 1, at, refs));
        }
    }
    None
}

/// Whether every corner lies on one side of every triangle's plane (the
/// same side for all, within a relative 1e-6 of the piece's size and
/// its coordinates'): a closed surface of supporting planes bounds its
/// corners' convex hull.
fn convex(tris: &[[Vec3; 3]], slots: &[u32], corners: &[Vec3]) -> bool {
    let [lo, hi] = bounds(corners);
    // A relative 1e-6 of the piece's size, and of its coordinates' size
    // (the f32 corners of a turned box are coplanar within their rounding,
    // about 1e-7 of the coordinates).
    let size = f64::from((hi - lo).max_element()) + f64::from(lo.abs().max(hi.abs()).max_element());
    let mut sign = 0.0f64;
    for &s in slots {
        let t = tris[s as usize].map(|v| v.as_dvec3());
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let len = n.length();
        if !(len > 0.0) {
            return false;
        }
        let tol = 1e-6 * len * size;
        for v in corners {
            let d = n.dot(v.as_dvec3() - t[0]);
            if d.abs() <= tol {
                continue;
            }
            if sign == 0.0 {
                sign = d.signum();
            } else if d.signum() != sign {
                return false;
            }
        }
    }
    sign != 0.0
}

/// The samples piece `corners` hides from `o` (segments t in (t0, t1)),
/// as the half-planes of its outline on the light, with `side` added;
/// None where its triangles must be marked one by one instead.
pub(crate) fn outline(
    corners: &[Vec3],
    o: Vec3,
    t0: f32,
    t1: f32,
    side: Option<HalfPlane>,
) -> Option<Cover> {
    // The depths `cover::cover` drops its end planes for, every corner.
    let margin = 1.0 + 1e-3;
    let near = (1.0 - t1) * o.z * margin;
    let far = (1.0 - t0) * o.z;
    if !corners.iter().all(|v| v.z > near && v.z * margin < far) {
        return None;
    }
    let od = o.as_dvec3();
    let a: Vec<DVec3> = corners.iter().map(|v| v.as_dvec3() - od).collect();
    // The corners seen from o on z = 0: o + a (o.z / (o.z - v.z)) = o - a o.z / a.z.
    let p: Vec<DVec2> = a
        .iter()
        .map(|a| od.truncate() - a.truncate() * (od.z / a.z))
        .collect();
    let hull = hull(&p);
    let n = hull.len();
    if n < 3 || n + usize::from(side.is_some()) > PLANES {
        return None;
    }
    let mid = hull.iter().map(|&k| p[k]).sum::<DVec2>() / n as f64;
    let mut c = Cover::new();
    for e in 0..n {
        let (i, j) = (hull[e], hull[(e + 1) % n]);
        let m = a[i].cross(a[j]);
        // m · d at the outline's centre (d = s - o), its sign the inside's.
        let inside = m.x * (mid.x - od.x) + m.y * (mid.y - od.y) - m.z * od.z;
        if !(inside.abs() > 0.0) || !inside.is_finite() {
            return None;
        }
        let k = inside.signum();
        c = c.and(HalfPlane {
            a: (k * (-m.dot(od))) as f32,
            b: (k * m.x) as f32,
            c: (k * m.y) as f32,
            strict: false,
        });
    }
    if let Some(s) = side {
        c = c.and(s);
    }
    Some(c)
}

/// The convex hull of `p` (Andrew's monotone chain), counter-clockwise,
/// as indices; corners on a hull edge are left out.
fn hull(p: &[DVec2]) -> Vec<usize> {
    let mut k: Vec<usize> = (0..p.len()).collect();
    k.sort_unstable_by(|&i, &j| p[i].x.total_cmp(&p[j].x).then(p[i].y.total_cmp(&p[j].y)));
    let turns_left = |h: &[usize], i: usize| {
        let (o, a) = (p[h[h.len() - 2]], p[h[h.len() - 1]]);
        (a - o).perp_dot(p[i] - o) > 0.0
    };
    // The lower chain left to right, then the upper one right to left
    // (starting at the lower one's last corner, which it never pops).
    let mut h: Vec<usize> = Vec::with_capacity(2 * p.len());
    for &i in &k {
        while h.len() >= 2 && !turns_left(&h, i) {
            h.pop();
        }
        h.push(i);
    }
    let floor = h.len() + 1;
    for &i in k.iter().rev().skip(1) {
        while h.len() >= floor && !turns_left(&h, i) {
            h.pop();
        }
        h.push(i);
    }
    // The upper chain ends where the lower began.
    h.pop();
    h
}
