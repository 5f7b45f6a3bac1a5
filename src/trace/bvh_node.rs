//! A node of the binary BVH (`bvh.rs`), which the wide BVH (`bvh_wide.rs`)
//! collapses: its own file so that both read it and neither reads the other
//! back.

use glam::Vec3;

/// A binary node: its bounds, and its triangles (a leaf) or its children.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub(crate) min: Vec3,
    pub(crate) max: Vec3,
    /// Leaf: first triangle; inner: index of the left child (right = left + 1).
    pub(crate) start: u32,
    /// Triangles in a leaf; 0 for an inner node.
    pub(crate) count: u32,
}
