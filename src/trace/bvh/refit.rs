//! Refitting: a tree built once reused over other coordinates of the same
//! triangles (issue 29, "prepare once, render many": a scene seen through
//! another camera, lit by a light of the same orientation, is the same
//! triangles in another light space).
//!
//! The topology (which triangles each leaf holds, which nodes each node
//! holds) is kept and every box is recomputed bottom-up from the triangles'
//! new corners (Wald, Boulos & Shirley 2007, "Ray tracing deformable scenes
//! using dynamic bounding volume hierarchies": refitting instead of
//! rebuilding). A box is the min and max of its triangles' corners, exactly
//! as `build` takes it, so the refitted tree is the tree a build that made
//! these splits would give, and a ray's answer never depends on the
//! topology (any hit: the triangle tests are the same; nearest: the nearest
//! of the same candidates). Only the speed does: splits chosen in one space
//! are the SAH's best there, and the nearer the new space is to it (a
//! translation and a uniform scale: the same; a light of the same frame
//! focused on other points: close), the closer the tree stays to a fresh
//! SAH build.

use super::{bounds, Bvh};
use crate::trace::bvh_wide::refit_slots;
use glam::Vec3;
use rayon::prelude::*;

/// A tree's shape without its coordinates (its nodes' boxes are those it
/// was built with, and never read): what a refit reads, kept between calls
/// without the triangles (36 of the tree's 120-odd bytes a triangle).
pub struct Topology(Bvh);

impl Bvh {
    /// This tree's shape, the tree consumed (nothing copied).
    pub fn into_topology(self) -> Topology {
        Topology(Bvh {
            tris: vec![],
            ..self
        })
    }

    /// This tree's shape, copied.
    pub fn topology(&self) -> Topology {
        Topology(Bvh {
            nodes: self.nodes.clone(),
            tris: vec![],
            order: self.order.clone(),
            wide: self.wide.clone(),
            wide_parent: self.wide_parent.clone(),
            wide_source: self.wide_source.clone(),
            derived: self.derived.clone(),
        })
    }
}

impl Topology {
    /// The tree over `tris`: the triangles it was built over, in their
    /// input order, at other coordinates. `None` when the count differs
    /// (not the same triangles).
    pub fn refit(&self, tris: &[[Vec3; 3]]) -> Option<Bvh> {
        let t = &self.0;
        if tris.len() != t.order.len() {
            return None;
        }
        // The triangles in the tree's order.
        let moved: Vec<[Vec3; 3]> = t.order.par_iter().map(|&i| tris[i as usize]).collect();
        // Leaves in parallel (copied and fitted in one pass: a clone first
        // was a serial copy of 40 MB on 2 000 000 triangles), then inner
        // nodes from the last to the first: every build numbers a node's
        // children after it (`subtree`, `serial_subtree`), so both are
        // final when their parent is read.
        let mut nodes: Vec<_> = t
            .nodes
            .par_iter()
            .map(|&n| {
                let mut n = n;
                if n.count > 0 {
                    let s = n.start as usize;
                    (n.min, n.max) = bounds(moved[s..s + n.count as usize].iter());
                }
                n
            })
            .collect();
        if !moved.is_empty() {
            for k in (0..nodes.len()).rev() {
                let n = nodes[k];
                if n.count == 0 {
                    let (l, r) = (nodes[n.start as usize], nodes[n.start as usize + 1]);
                    debug_assert!(n.start as usize > k);
                    nodes[k].min = l.min.min(r.min);
                    nodes[k].max = l.max.max(r.max);
                }
            }
        }
        let wide = t
            .wide
            .par_iter()
            .map(|&w| {
                let mut w = w;
                refit_slots(&mut w, &nodes, &t.wide_source);
                w
            })
            .collect();
        Some(Bvh {
            nodes,
            tris: moved,
            order: t.order.clone(),
            wide,
            wide_parent: t.wide_parent.clone(),
            wide_source: t.wide_source.clone(),
            derived: t.derived.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{random_tris as scene, rng};
    use super::*;
    use crate::trace::packet::{Rays, ALL, LANES};

    /// The triangles in another frame: rotated about z and x, scaled,
    /// moved (what another light space does to them).
    fn moved(tris: &[[Vec3; 3]]) -> Vec<[Vec3; 3]> {
        let rot = glam::Mat3::from_rotation_z(0.7) * glam::Mat3::from_rotation_x(0.3);
        tris.iter()
            .map(|t| t.map(|v| rot * v * 1.5 + Vec3::new(0.3, -0.2, 4.0)))
            .collect()
    }

    #[test]
    fn a_refitted_tree_holds_the_boxes_a_build_of_its_splits_gives() {
        // Over PARALLEL_TRIS: the top of the tree was built in parallel
        // (its nodes numbered by merging), the rest by one thread.
        let tris = scene(3 * super::super::PARALLEL_TRIS + 5, 3);
        let built = Bvh::build(tris.clone());
        let new = moved(&tris);
        let refit = built.topology().refit(&new).unwrap();
        assert_eq!(refit.order, built.order);
        for (k, n) in refit.nodes.iter().enumerate() {
            // Every node's box is the exact bounds of its triangles.
            let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            let mut work = vec![k];
            while let Some(j) = work.pop() {
                let m = refit.nodes[j];
                if m.count > 0 {
                    let s = m.start as usize;
                    let (a, b) = bounds(refit.tris[s..s + m.count as usize].iter());
                    (lo, hi) = (lo.min(a), hi.max(b));
                } else {
                    work.extend([m.start as usize, m.start as usize + 1]);
                }
            }
            assert_eq!((n.min, n.max), (lo, hi), "node {k}");
        }
        // The wide nodes are those of the refitted binary tree.
        let (wide, _, _) = crate::trace::bvh_wide::collapse(&refit.nodes);
        for (a, b) in wide.iter().zip(&refit.wide) {
            assert_eq!((a.lo, a.hi, a.child), (b.lo, b.hi, b.child));
        }
        assert!(built.topology().refit(&new[1..]).is_none());
        assert!(Bvh::build(vec![]).topology().refit(&[]).unwrap().is_empty());
    }

    #[test]
    fn rays_through_a_refitted_tree_answer_as_through_a_fresh_build() {
        let tris = scene(2000, 5);
        let new = moved(&tris);
        let refit = Bvh::build(tris).into_topology().refit(&new).unwrap();
        let fresh = Bvh::build(new.clone());
        let mut r = rng(9);
        for _ in 0..300 {
            let o: [Vec3; LANES] = std::array::from_fn(|_| {
                Vec3::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0, 1.0 + r() * 8.0)
            });
            let d: [Vec3; LANES] = std::array::from_fn(|i| {
                Vec3::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0, r() * 8.0) - o[i]
            });
            for i in 0..LANES {
                assert_eq!(
                    refit.occluded(o[i], d[i], 1e-5, 1.0),
                    fresh.occluded(o[i], d[i], 1e-5, 1.0)
                );
                assert_eq!(
                    refit.nearest(o[i], d[i], f32::INFINITY),
                    fresh.nearest(o[i], d[i], f32::INFINITY)
                );
            }
            let rays = Rays::new(o, d);
            assert_eq!(
                refit.occluded_lanes(0, &rays, ALL, 1e-5, 1.0).0,
                fresh.occluded_lanes(0, &rays, ALL, 1e-5, 1.0).0
            );
        }
    }
}
