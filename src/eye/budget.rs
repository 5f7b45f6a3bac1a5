//! What an eye-view call that traces (`exact`, the default) allocates, added
//! up before anything is, so that a scene or an image too large for the
//! machine is refused with its size instead of aborting the process when an
//! allocation fails (`crate::memory`).
//!
//! Bytes per triangle, per vertex and per pixel, from the types that hold
//! them: the gathered triangles (`SceneTriangles`: f64 corners 72, faces 12,
//! mesh 4), the light-space triangles the tree is built over (36), the tree
//! (`Bvh`: triangles and edges 72, input order 4; at most one binary node of
//! 32 bytes and a third of a four-wide node of 128 a triangle, with their
//! parents and sources), the shape a preparation keeps (its nodes, order,
//! wide nodes: 90); per vertex the f64 world and light-space copies (48); per
//! pixel the G-buffer (depth 4, position 24, normal 12, mesh 4), the framing
//! of a visible point (position 24, normal 12, light space 24, index 8, ray
//! start 32), the visibility, and the shaded and unshadowed images (4 + 24).
//! A bound, not a measurement: the allocator and rayon's buffers add to it.

/// Bytes of a traced eye-view call over `triangles` triangles of
/// `vertices` vertices seen at `pixels` pixels.
pub fn traced_bytes(triangles: usize, vertices: usize, pixels: usize) -> u64 {
    const PER_TRIANGLE: u64 = 72 + 12 + 4 + 36 + (72 + 4 + 32 + 128 / 3 + 8) + 90;
    const PER_VERTEX: u64 = 48;
    const PER_PIXEL: u64 = 44 + 100 + 4 + 24;
    (triangles as u64)
        .saturating_mul(PER_TRIANGLE)
        .saturating_add((vertices as u64).saturating_mul(PER_VERTEX))
        .saturating_add((pixels as u64).saturating_mul(PER_PIXEL))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_grows_with_each_count_and_saturates() {
        let base = traced_bytes(1000, 500, 10_000);
        assert!(traced_bytes(2000, 500, 10_000) > base);
        assert!(traced_bytes(1000, 600, 10_000) > base);
        assert!(traced_bytes(1000, 500, 20_000) > base);
        assert_eq!(traced_bytes(usize::MAX, usize::MAX, usize::MAX), u64::MAX);
        // 2 000 000 triangles at 1920 x 1080: about 1.2 GB, under the 2 GB
        // issue 29 allows such a call.
        let big = traced_bytes(2_000_000, 1_000_000, 1920 * 1080);
        assert!((1_000_000_000..2_000_000_000).contains(&big), "{big}");
    }
}
