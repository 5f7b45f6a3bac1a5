//! The shadow rays of one receiver, traced as a packet: they all leave a
//! small box of origins (one point in the light view; the two offset
//! origins of a surface point in the eye view) for the light rectangle, so
//! they lie inside one shaft (the convex hull of the origins and the
//! light; Haines & Wallace 1994, "Shaft culling for efficient ray-cast
//! radiosity").
//!
//! Once per receiver, the BVH is traversed with the shaft instead of a ray,
//! which collects the leaves a ray of the packet could enter:
//! * none: every ray is clear (the receiver is lit) without tracing one;
//! * a few (up to `MAX_LEAVES`): each ray tests those leaves only;
//! * more: each ray traverses the whole tree, as before.
//!
//! And the subtree (`CACHE_LEVELS` above the leaf, up to 16 triangles)
//! that blocked the previous blocked ray is searched first (a shadow
//! cache, after Haines & Greenberg 1986): neighbouring light samples are
//! usually blocked by nearby triangles. A single leaf hit only 4% of the
//! rays on the floating bunny (its triangles back-project to about one
//! light sample each); the subtree costs a few more box tests per ray and
//! was faster. Of 0 (the leaf), 2, 3, 4 and 6 levels, 2 gave the smallest
//! total time over the four study scenes, 3 within noise of it (timed by
//! benchmarks/time_exact.py; the 0 and 2 rows are in docs/methods/exact.md).
//!
//! The answer per ray is the one `Bvh::occluded` gives: a leaf's slab test
//! passes only if its ancestors' do (`Bvh::leaf_occludes`), the order in
//! which leaves and subtrees are searched does not change an any-hit
//! answer, and the shaft test is
//! conservative, by a margin of `MARGIN` times the scene's size for the
//! rounding of the ray tests.
//!
//! Shaft at depth z: a ray from origin o (o.z > 0) to the light point
//! (x, y, 0) is L + s (o - L), s in [0, 1], at depth s o.z. For a node
//! whose depths are [z0, z1], s lies in [z0 / max o.z, z1 / min o.z], and
//! the ray's x there in [(1 - s)(-Lx/2) + s min o.x, (1 - s) Lx/2 + s max
//! o.x]: both ends linear in s, so their extremes over the s range are at
//! its ends. The node can be entered only if its box meets that x range,
//! and the y one.

use super::bvh::Bvh;
use glam::Vec3;

/// Leaves a packet tests by itself; more, and each ray traverses the tree.
const MAX_LEAVES: usize = 32;
/// The shadow cache holds the subtree this many levels above the leaf
/// that blocked the last blocked ray.
const CACHE_LEVELS: u32 = 2;
/// The shaft test's margin, relative to the scene's size.
const MARGIN: f32 = 1e-5;

/// One receiver's shadow rays.
pub(crate) struct Packet<'a> {
    bvh: &'a Bvh,
    leaves: [u32; MAX_LEAVES],
    count: usize,
    /// More than `MAX_LEAVES` leaves, or no shaft (an origin at or behind
    /// the light's plane): every ray traverses the tree.
    whole_tree: bool,
    /// The subtree that blocked the last blocked ray (`CACHE_LEVELS`
    /// above its leaf).
    cache: Option<u32>,
}

impl<'a> Packet<'a> {
    /// The packet of rays leaving the box [olo, ohi] for the light
    /// [-half[0], half[0]] x [-half[1], half[1]] at z = 0.
    pub(crate) fn new(bvh: &'a Bvh, olo: Vec3, ohi: Vec3, half: [f32; 2]) -> Packet<'a> {
        let mut p = Packet {
            bvh,
            leaves: [0; MAX_LEAVES],
            count: 0,
            whole_tree: false,
            cache: None,
        };
        if bvh.is_empty() {
            return p;
        }
        let nodes = &bvh.nodes;
        let root = nodes[0];
        let scale = root
            .min
            .abs()
            .max(root.max.abs())
            .max(olo.abs())
            .max(ohi.abs())
            .max_element()
            .max(half[0].abs())
            .max(half[1].abs());
        let m = MARGIN * (1.0 + scale);
        if !(olo.z > 0.0 && ohi.z.is_finite() && m.is_finite()) {
            p.whole_tree = true;
            return p;
        }
        let meets = |k: u32| {
            let n = &nodes[k as usize];
            let (z0, z1) = (n.min.z - m, n.max.z + m);
            let s_lo = (z0 / ohi.z).max(0.0);
            let s_hi = (z1 / olo.z).min(1.0);
            if !(s_lo <= s_hi) {
                return false;
            }
            (0..2).all(|a| {
                let lo = |s: f32| (1.0 - s) * -half[a] + s * olo[a];
                let hi = |s: f32| (1.0 - s) * half[a] + s * ohi[a];
                let x0 = lo(s_lo).min(lo(s_hi)) - m;
                let x1 = hi(s_lo).max(hi(s_hi)) + m;
                n.max[a] >= x0 && n.min[a] <= x1
            })
        };
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let k = stack[sp];
            if !meets(k) {
                continue;
            }
            let n = &nodes[k as usize];
            if n.count > 0 {
                if p.count == MAX_LEAVES {
                    p.whole_tree = true;
                    return p;
                }
                p.leaves[p.count] = k;
                p.count += 1;
            } else {
                // Depth-bounded trees (bvh.rs): one pending sibling a level.
                debug_assert!(sp + 2 <= stack.len());
                stack[sp] = n.start;
                stack[sp + 1] = n.start + 1;
                sp += 2;
            }
        }
        p
    }

    /// No ray of the packet can hit a triangle.
    pub(crate) fn is_clear(&self) -> bool {
        !self.whole_tree && self.count == 0
    }

    /// Whether the segment o + t d, t in (t0, t1), of this packet hits a
    /// triangle (as `Bvh::occluded` answers).
    pub(crate) fn occluded(&mut self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> bool {
        if let Some(c) = self.cache {
            if let Some(leaf) = self.bvh.occluding_leaf(c, o, d, t0, t1) {
                self.cache = Some(self.bvh.ancestor(leaf, CACHE_LEVELS));
                return true;
            }
        }
        let hit = if self.whole_tree {
            self.bvh.occluding_leaf(0, o, d, t0, t1)
        } else {
            let inv = d.recip();
            self.leaves[..self.count]
                .iter()
                .copied()
                .find(|&leaf| self.bvh.leaf_occludes(leaf, o, d, inv, t0, t1))
        };
        if let Some(leaf) = hit {
            self.cache = Some(self.bvh.ancestor(leaf, CACHE_LEVELS));
        }
        hit.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::bvh::tests::rng;

    /// Small triangles at depths 1.5 to 2.5 (the light is at 0).
    fn scene(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
        let mut r = rng(seed);
        (0..n)
            .map(|_| {
                let c = Vec3::new(r() * 3.0 - 1.5, r() * 3.0 - 1.5, 1.5 + r());
                [
                    c,
                    c + Vec3::new(r() * 0.2, r() * 0.05, r() * 0.05),
                    c + Vec3::new(r() * 0.05, r() * 0.2, r() * 0.05),
                ]
            })
            .collect()
    }

    #[test]
    fn a_packet_answers_every_ray_as_the_tree_does() {
        // Sparse and dense scenes (few leaves per shaft, and more than
        // MAX_LEAVES), one origin and a box of two, every ray of a grid.
        let half = [0.4, 0.3];
        for (n, seed) in [(20, 1), (300, 2), (3000, 3)] {
            let bvh = Bvh::build(scene(n, seed));
            let mut r = rng(seed + 10);
            let (mut clear, mut whole) = (0, 0);
            for _ in 0..200 {
                let a = Vec3::new(r() * 8.0 - 4.0, r() * 8.0 - 4.0, 3.0 + r());
                let b = a + Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 1e-3;
                let mut p = Packet::new(&bvh, a.min(b), a.max(b), half);
                clear += p.is_clear() as u32;
                whole += p.whole_tree as u32;
                for j in 0..16 {
                    for i in 0..16 {
                        let l = Vec3::new(
                            (i as f32 + 0.5) / 16.0 * 2.0 * half[0] - half[0],
                            (j as f32 + 0.5) / 16.0 * 2.0 * half[1] - half[1],
                            0.0,
                        );
                        let o = if (i + j) % 2 == 0 { a } else { b };
                        let want = bvh.occluded(o, l - o, 1e-5, 1.0 - 1e-5);
                        assert!(!(p.is_clear() && want), "a clear packet's ray is blocked");
                        assert_eq!(p.occluded(o, l - o, 1e-5, 1.0 - 1e-5), want);
                    }
                }
            }
            // Each scene exercises what it is there for.
            match n {
                20 => assert!(clear > 0),
                3000 => assert!(whole > 0),
                _ => assert!(clear < 200 && whole < 200),
            }
        }
    }

    #[test]
    fn an_origin_at_the_light_plane_traverses_the_whole_tree() {
        let bvh = Bvh::build(scene(50, 4));
        let p = Packet::new(
            &bvh,
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            [0.5, 0.5],
        );
        assert!(p.whole_tree && !p.is_clear());
    }

    #[test]
    fn an_empty_tree_is_clear() {
        let bvh = Bvh::build(vec![]);
        let mut p = Packet::new(&bvh, Vec3::splat(1.0), Vec3::splat(1.0), [0.5, 0.5]);
        assert!(p.is_clear());
        assert!(!p.occluded(Vec3::splat(1.0), -Vec3::splat(1.0), 0.0, 1.0));
    }
}
