//! Shaft culling: the shadow rays from a box of origins (one receiver
//! point in the light view, the two offset origins of a surface point in
//! the eye view, or a packet's eight receivers) to a rectangle of the light
//! (the whole light, or a region of its strata) lie inside one shaft, the
//! convex hull of the origins and the rectangle (Haines & Wallace 1994,
//! "Shaft culling for efficient ray-cast radiosity"). The BVH is traversed
//! once with the shaft instead of a ray: if no leaf meets it, every ray of
//! the shaft is clear and none is traced (`exact.rs`).
//!
//! The test is conservative, by a margin of `MARGIN` times the scene's size
//! for the rounding of the ray tests: a shaft found clear holds no ray that
//! `Bvh::occluded` finds blocked.
//!
//! Shaft at depth z: a ray from origin o (o.z > 0) to the light point
//! (x, y, 0) is L + s (o - L), s in [0, 1], at depth s o.z. For a node
//! whose depths are [z0, z1], s lies in [z0 / max o.z, z1 / min o.z], and
//! the ray's x there in [(1 - s) x0 + s min o.x, (1 - s) x1 + s max o.x]
//! for the rectangle [x0, x1] x [y0, y1]: both ends linear in s, so their
//! extremes over the s range are at its ends. The node can be entered only
//! if its box meets that x range, and the y one.

use super::bvh::Bvh;
use super::bvh_node::Node;
use glam::Vec3;

/// The shaft test's margin, relative to the scene's size.
const MARGIN: f32 = 1e-5;

/// The rays from the origin box [olo, ohi] to the light rectangle
/// [x0, x1] x [y0, y1] at z = 0.
pub(crate) struct Shaft {
    olo: Vec3,
    ohi: Vec3,
    rect: [[f32; 2]; 2],
    /// The margin, in scene units.
    m: f32,
}

impl Shaft {
    /// The shaft, or `None` where an origin lies at or behind the light's
    /// plane (no shaft bounds its rays).
    pub(crate) fn new(bvh: &Bvh, olo: Vec3, ohi: Vec3, rect: [[f32; 2]; 2]) -> Option<Shaft> {
        let root = bvh.nodes[0];
        let scale = root
            .min
            .abs()
            .max(root.max.abs())
            .max(olo.abs())
            .max(ohi.abs())
            .max_element()
            .max(rect[0][0].abs().max(rect[0][1].abs()))
            .max(rect[1][0].abs().max(rect[1][1].abs()));
        let m = MARGIN * (1.0 + scale);
        (olo.z > 0.0 && ohi.z.is_finite() && m.is_finite()).then_some(Shaft { olo, ohi, rect, m })
    }

    /// Whether a ray of the shaft could enter `n`'s box.
    #[inline]
    pub(crate) fn meets(&self, n: &Node) -> bool {
        self.meets_box(n.min, n.max)
    }

    /// Whether a ray of the shaft could enter the box [min, max].
    #[inline]
    fn meets_box(&self, min: Vec3, max: Vec3) -> bool {
        let (olo, ohi, m) = (self.olo, self.ohi, self.m);
        let (z0, z1) = (min.z - m, max.z + m);
        let s_lo = (z0 / ohi.z).max(0.0);
        let s_hi = (z1 / olo.z).min(1.0);
        if !(s_lo <= s_hi) {
            return false;
        }
        (0..2).all(|a| {
            let [l0, l1] = self.rect[a];
            let lo = |s: f32| (1.0 - s) * l0 + s * olo[a];
            let hi = |s: f32| (1.0 - s) * l1 + s * ohi[a];
            let x0 = lo(s_lo).min(lo(s_hi)) - m;
            let x1 = hi(s_lo).max(hi(s_hi)) + m;
            max[a] >= x0 && min[a] <= x1
        })
    }
}

/// Whether no segment from the box [olo, ohi] to a point of the light
/// rectangle `rect` ([x0, x1], [y0, y1] at z = 0) can hit a triangle: no
/// leaf of the tree meets their shaft. Conservative: `false` when unsure.
pub(crate) fn is_clear(bvh: &Bvh, olo: Vec3, ohi: Vec3, rect: [[f32; 2]; 2]) -> bool {
    if bvh.is_empty() {
        return true;
    }
    let Some(shaft) = Shaft::new(bvh, olo, ohi, rect) else {
        return false;
    };
    let nodes = &bvh.nodes;
    let mut stack = [0u32; 64];
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let n = &nodes[stack[sp] as usize];
        if !shaft.meets(n) {
            continue;
        }
        if n.count > 0 {
            return false;
        }
        // Depth-bounded trees (bvh.rs): one pending sibling a level.
        debug_assert!(sp + 2 <= stack.len());
        stack[sp] = n.start;
        stack[sp + 1] = n.start + 1;
        sp += 2;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::bvh::tests::rng;

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
    fn no_ray_of_a_clear_shaft_is_blocked() {
        // Sparse and dense scenes, one origin and a box of two, the whole
        // light and a quarter of it, every ray of a grid in the rectangle.
        let half = [0.4, 0.3];
        for (n, seed) in [(20, 1), (300, 2), (3000, 3)] {
            let bvh = Bvh::build(scene(n, seed));
            let mut r = rng(seed + 10);
            let mut clear = 0;
            for case in 0..400 {
                let a = Vec3::new(r() * 8.0 - 4.0, r() * 8.0 - 4.0, 3.0 + r());
                let b = a + Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * 1e-3;
                let rect = if case % 2 == 0 {
                    [[-half[0], half[0]], [-half[1], half[1]]]
                } else {
                    [[0.0, half[0]], [-half[1], 0.0]]
                };
                let is = is_clear(&bvh, a.min(b), a.max(b), rect);
                clear += is as u32;
                let mut blocked = false;
                for j in 0..16 {
                    for i in 0..16 {
                        let x = rect[0][0] + (i as f32 + 0.5) / 16.0 * (rect[0][1] - rect[0][0]);
                        let y = rect[1][0] + (j as f32 + 0.5) / 16.0 * (rect[1][1] - rect[1][0]);
                        let o = if (i + j) % 2 == 0 { a } else { b };
                        blocked |= bvh.occluded(o, Vec3::new(x, y, 0.0) - o, 1e-5, 1.0 - 1e-5);
                    }
                }
                assert!(!(is && blocked), "a clear shaft's ray is blocked");
            }
            // Each scene exercises what it is there for.
            match n {
                20 => assert!(clear > 0),
                3000 => assert!(clear < 400),
                _ => assert!(clear > 0 && clear < 400),
            }
        }
    }

    #[test]
    fn an_origin_at_the_light_plane_is_never_clear() {
        let bvh = Bvh::build(scene(50, 4));
        let rect = [[-0.5, 0.5], [-0.5, 0.5]];
        assert!(!is_clear(&bvh, Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), rect));
    }

    #[test]
    fn an_empty_tree_is_clear() {
        let bvh = Bvh::build(vec![]);
        let rect = [[-0.5, 0.5], [-0.5, 0.5]];
        assert!(is_clear(&bvh, Vec3::splat(1.0), Vec3::splat(1.0), rect));
    }
}
