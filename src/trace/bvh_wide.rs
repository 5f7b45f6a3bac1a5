//! The binary BVH collapsed to four-wide nodes, for the CPU's packet
//! traversal (`packet.rs`).
//!
//! Each wide node holds the boxes of up to four binary nodes: the
//! grandchildren of a binary node, or a child where that child is a leaf
//! (Wald et al. 2008, "Getting rid of packets": multi-branching BVHs by
//! collapsing a binary one). A packet tests the four boxes one after the
//! other with no dependence between them, which the processor overlaps,
//! where the binary tree tests one node, branches on it, loads the next:
//! half the levels, half the dependent loads and mispredicted branches.
//!
//! The boxes are the binary nodes' own, bit for bit, and the leaves the
//! binary leaves: a lane enters a leaf exactly when it enters that leaf in
//! the binary tree, so every ray's answer is the binary tree's (and the
//! GPU's, which traverses the binary tree).

use super::bvh_node::Node;

/// No child in this slot.
const EMPTY: u32 = u32::MAX;

/// Up to four children, their boxes by axis then slot.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Wide {
    pub(crate) lo: [[f32; 4]; 3],
    pub(crate) hi: [[f32; 4]; 3],
    /// An inner child: its wide node; a leaf: its binary node.
    pub(crate) child: [u32; 4],
    /// Children in use (the first `len` slots).
    pub(crate) len: u32,
    /// Bit k: slot k is a leaf.
    pub(crate) leaves: u32,
    _pad: [u32; 2],
}

/// The wide nodes of the binary tree `nodes` (root first; a root that is
/// a leaf is the one slot of the one wide node), each wide node's parent
/// (the root's is itself) and the binary node each one was made from (whose
/// box its slot in the parent holds: `Bvh::refit` reads it).
pub(crate) fn collapse(nodes: &[Node]) -> (Vec<Wide>, Vec<u32>, Vec<u32>) {
    // An empty tree is a root leaf of no triangles.
    if nodes.is_empty() || (nodes.len() == 1 && nodes[0].count == 0) {
        return (vec![], vec![], vec![]);
    }
    let mut wide = vec![empty()];
    let mut parent = vec![0u32];
    let mut source = vec![0u32];
    if nodes[0].count > 0 {
        wide[0] = slots(nodes, &[0], |_| unreachable!());
        return (wide, parent, source);
    }
    // (binary inner node, the wide node it becomes)
    let mut work = vec![(0u32, 0usize)];
    while let Some((b, w)) = work.pop() {
        let n = nodes[b as usize];
        let mut children = Vec::with_capacity(4);
        for c in [n.start, n.start + 1] {
            let cn = nodes[c as usize];
            if cn.count > 0 {
                children.push(c);
            } else {
                children.extend([cn.start, cn.start + 1]);
            }
        }
        wide[w] = slots(nodes, &children, |c| {
            let k = wide.len();
            work.push((c, k));
            wide.push(empty());
            parent.push(w as u32);
            source.push(c);
            k as u32
        });
    }
    (wide, parent, source)
}

/// Slot `k`'s boxes of wide node `w` set again from the binary nodes
/// `nodes` (refitted): a leaf slot's from its binary leaf, an inner one's
/// from the binary node its wide child was made from (`source`).
pub(crate) fn refit_slots(w: &mut Wide, nodes: &[Node], source: &[u32]) {
    for k in 0..w.len as usize {
        let b = if w.leaves & (1 << k) != 0 {
            w.child[k]
        } else {
            source[w.child[k] as usize]
        };
        let n = nodes[b as usize];
        for a in 0..3 {
            w.lo[a][k] = n.min[a];
            w.hi[a][k] = n.max[a];
        }
    }
}

/// A wide node whose slots are the binary nodes `children`; `inner(c)`
/// gives the wide node an inner child becomes.
fn slots(nodes: &[Node], children: &[u32], mut inner: impl FnMut(u32) -> u32) -> Wide {
    let mut node = empty();
    node.len = children.len() as u32;
    for (k, &c) in children.iter().enumerate() {
        let cn = nodes[c as usize];
        for a in 0..3 {
            node.lo[a][k] = cn.min[a];
            node.hi[a][k] = cn.max[a];
        }
        if cn.count > 0 {
            node.child[k] = c;
            node.leaves |= 1 << k;
        } else {
            node.child[k] = inner(c);
        }
    }
    node
}

fn empty() -> Wide {
    Wide {
        lo: [[0.0; 4]; 3],
        hi: [[0.0; 4]; 3],
        child: [EMPTY; 4],
        len: 0,
        leaves: 0,
        _pad: [0; 2],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::bvh::{tests::rng, Bvh};
    use glam::Vec3;

    #[test]
    fn every_binary_leaf_is_in_one_slot_with_its_own_box() {
        let mut r = rng(11);
        let tris: Vec<[Vec3; 3]> = (0..777)
            .map(|_| {
                let c = Vec3::new(r(), r(), r()) * 4.0;
                [c, c + Vec3::X * 0.1 * r(), c + Vec3::Y * 0.1 * r()]
            })
            .collect();
        let bvh = Bvh::build(tris);
        let (wide, parent, source) = collapse(&bvh.nodes);
        assert_eq!(parent.len(), wide.len());
        assert_eq!(source.len(), wide.len());
        let mut seen = vec![0; bvh.nodes.len()];
        for (i, w) in wide.iter().enumerate() {
            assert!((2..=4).contains(&w.len));
            for k in 0..w.len as usize {
                if w.leaves & (1 << k) == 0 {
                    assert_eq!(parent[w.child[k] as usize] as usize, i);
                }
            }
            for k in 0..w.len as usize {
                if w.leaves & (1 << k) != 0 {
                    let n = bvh.nodes[w.child[k] as usize];
                    assert!(n.count > 0);
                    seen[w.child[k] as usize] += 1;
                    for a in 0..3 {
                        assert_eq!(w.lo[a][k].to_bits(), n.min[a].to_bits());
                        assert_eq!(w.hi[a][k].to_bits(), n.max[a].to_bits());
                    }
                }
            }
        }
        for (k, n) in bvh.nodes.iter().enumerate() {
            assert_eq!(seen[k], (n.count > 0) as u32, "node {k}");
        }
    }

    #[test]
    fn a_single_leaf_is_the_one_slot_of_the_root() {
        let bvh = Bvh::build(vec![[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let (wide, parent, source) = collapse(&bvh.nodes);
        assert_eq!(
            (wide.len(), parent, source, wide[0].len, wide[0].leaves),
            (1, vec![0], vec![0], 1, 1)
        );
        assert!(collapse(&Bvh::build(vec![]).nodes).0.is_empty());
    }
}
