//! A bounding volume hierarchy over triangles, for shadow rays (any hit) and
//! camera rays (nearest hit), shared by `exact`, the eye view and the GPU
//! twins (which traverse the same nodes, uploaded).
//!
//! Build: binned surface area heuristic (SAH; Wald 2007, "On fast
//! construction of SAH-based bounding volume hierarchies"). A split of a
//! node of area A into children of areas A_l, A_r with n_l, n_r triangles is
//! expected to cost C_node + (A_l n_l + A_r n_r) / A * C_tri for a random ray
//! through the node; the build takes the cheapest of `BINS - 1` planes per
//! axis over the centroids' bounds, and splits every node of more than
//! `LEAF` triangles. Median splits (the earlier build) ignore how empty
//! space is distributed: on the study's scenes `exact` runs 1.2-1.3x faster
//! on the SAH tree (docs/methods/exact.md gives the numbers).
//!
//! Depth is bounded for the fixed 64-entry traversal stacks (CPU and WGSL):
//! below `SAH_DEPTH` levels the build falls back to median splits, which
//! halve the count each level, so no tree is deeper than `SAH_DEPTH` + 32.

use super::bvh_node::Node;
use super::bvh_wide::{collapse, Wide};
use glam::Vec3;

mod refit;
pub use refit::Topology;

/// The factor a slab test widens a box's exit t by, so that rounding never
/// culls a box that a ray crosses, a triangle in it included (Ize 2013,
/// "Robust BVH ray traversal", JCGT 2(2): 1 + 2 gamma_3, gamma_n = n u /
/// (1 - n u), u = 2^-24, bounds the rounding of the slab values; 4 ulps of
/// 1 is above it). Without it, 21 of 39 449 rays through shared edges and
/// corners of a grid hit a triangle (`hit_t`) that the tree did not let
/// them reach (`no_ray_slips_between_triangles_that_share_an_edge`). Every
/// path multiplies the slabs' minimum exit by it before clipping it to the
/// segment: the same bits.
pub(crate) const EXIT_SLACK: f32 = 1.0 + 4.0 * f32::EPSILON;

/// Triangles per BVH leaf at most.
const LEAF: usize = 4;
/// Levels built by SAH; deeper nodes split at the median.
const SAH_DEPTH: usize = 28;
/// Candidate planes per axis (bins - 1).
const BINS: usize = 16;

/// A bounding volume hierarchy over triangles.
pub struct Bvh {
    pub(crate) nodes: Vec<Node>,
    tris: Vec<[Vec3; 3]>,
    /// The index each triangle had in the input (`nearest` reports it).
    order: Vec<u32>,
    /// The tree collapsed to four-wide nodes (`bvh_wide.rs`), and each
    /// one's parent (for the shadow cache).
    pub(crate) wide: Vec<Wide>,
    wide_parent: Vec<u32>,
    /// The binary node each wide node was made from (`refit.rs`).
    wide_source: Vec<u32>,
    /// What a method derives from the tree's shape and the triangles'
    /// input order alone (the masks' closed pieces: `masks/pieces.rs`),
    /// made on first use and shared by the trees refitted from this one's
    /// shape (`refit.rs`), so that a prepared scene derives it once.
    derived: Derived,
}

/// `Bvh::derived`'s cell, shared between a tree, its shape and the trees
/// refitted from it.
pub(crate) type Derived =
    std::sync::Arc<std::sync::OnceLock<std::sync::Arc<dyn std::any::Any + Send + Sync>>>;

fn bounds<'a>(tris: impl Iterator<Item = &'a [Vec3; 3]>) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for t in tris {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    (lo, hi)
}

fn centroid(t: &[Vec3; 3]) -> Vec3 {
    (t[0] + t[1] + t[2]) * (1.0 / 3.0)
}

/// The bounds of the triangles' centroids (where split planes are chosen).
fn centroid_bounds(tris: &[([Vec3; 3], u32)]) -> (Vec3, Vec3) {
    tris.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), t| (a.min(centroid(&t.0)), b.max(centroid(&t.0))),
    )
}

/// Half the surface area of a box (the SAH needs ratios only); 0 for an
/// empty box.
fn half_area(lo: Vec3, hi: Vec3) -> f32 {
    let e = (hi - lo).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// The SAH split of `tris` (more than `LEAF` of them): the axis and the
/// plane on it (triangles whose centroid lies below it go left), or `None`
/// when every centroid is the same point (no plane separates them).
fn sah_split(tris: &[([Vec3; 3], u32)]) -> Option<(usize, f32)> {
    let (clo, chi) = centroid_bounds(tris);
    // Every axis's bins in one pass over the triangles, each triangle's box
    // and centroid taken once (three passes before, the same bins: the
    // `bvh` stage of docs/benchmarks/scale.md took 10% longer on the
    // 2 000 000-triangle mesh, 20% on the 125 000 one).
    let axes: [bool; 3] = std::array::from_fn(|a| chi[a] > clo[a]);
    let scale: [f32; 3] = std::array::from_fn(|a| BINS as f32 / (chi[a] - clo[a]));
    let mut count = [[0u32; BINS]; 3];
    let mut blo = [[Vec3::splat(f32::INFINITY); BINS]; 3];
    let mut bhi = [[Vec3::splat(f32::NEG_INFINITY); BINS]; 3];
    for (t, _) in tris {
        let (tlo, thi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        let c = centroid(t);
        for a in 0..3 {
            if axes[a] {
                let b = (((c[a] - clo[a]) * scale[a]) as usize).min(BINS - 1);
                count[a][b] += 1;
                blo[a][b] = blo[a][b].min(tlo);
                bhi[a][b] = bhi[a][b].max(thi);
            }
        }
    }
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        if !axes[axis] {
            continue;
        }
        let (lo, scale) = (clo[axis], scale[axis]);
        let (count, blo, bhi) = (&count[axis], &blo[axis], &bhi[axis]);
        // Sweep from the right: area and count of bins [k, BINS).
        let mut right = [(0f32, 0u32); BINS];
        let (mut lo_acc, mut hi_acc, mut n_acc) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        for k in (1..BINS).rev() {
            lo_acc = lo_acc.min(blo[k]);
            hi_acc = hi_acc.max(bhi[k]);
            n_acc += count[k];
            right[k] = (half_area(lo_acc, hi_acc), n_acc);
        }
        let (mut lo_acc, mut hi_acc, mut n_acc) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        for k in 1..BINS {
            lo_acc = lo_acc.min(blo[k - 1]);
            hi_acc = hi_acc.max(bhi[k - 1]);
            n_acc += count[k - 1];
            let (ar, nr) = right[k];
            if n_acc == 0 || nr == 0 {
                continue;
            }
            let cost = half_area(lo_acc, hi_acc) * n_acc as f32 + ar * nr as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + k as f32 / scale));
            }
        }
    }
    // The parent's area, C_node and C_tri rescale or shift every candidate
    // alike, so the cheapest plane is found without them; the node is split
    // whatever the cost, because leaves are capped at LEAF triangles.
    best.map(|(_, axis, plane)| (axis, plane))
}

impl Bvh {
    /// The nodes as the GPU twin (`gpu/exact.wgsl`) reads them: min xyz,
    /// max xyz (f32 bits), start, count: 8 words a node.
    #[cfg(feature = "gpu")]
    pub(crate) fn node_words(&self) -> Vec<u32> {
        self.nodes
            .iter()
            .flat_map(|n| {
                [
                    n.min.x.to_bits(),
                    n.min.y.to_bits(),
                    n.min.z.to_bits(),
                    n.max.x.to_bits(),
                    n.max.y.to_bits(),
                    n.max.z.to_bits(),
                    n.start,
                    n.count,
                ]
            })
            .collect()
    }

    /// The triangles in BVH order, 9 floats each.
    #[cfg(feature = "gpu")]
    pub(crate) fn triangle_floats(&self) -> Vec<f32> {
        self.tris
            .iter()
            .flat_map(|t| t.iter().flat_map(|v| v.to_array()))
            .collect()
    }

    /// The input index of the triangle in each BVH slot (what `nearest`
    /// reports), for the GPU twin's closest hits (`gpu/eye_hits.wgsl`).
    pub(crate) fn order(&self) -> &[u32] {
        &self.order
    }

    pub fn build(tris: Vec<[Vec3; 3]>) -> Bvh {
        Bvh::build_to(tris, Some(SAH_DEPTH))
    }

    /// A tree split along the Morton curve of the triangles' centroids (an
    /// LBVH, Lauterbach et al. 2009): one parallel sort instead of `build`'s
    /// SAH, several times faster to build and somewhat slower to trace. For
    /// a few thousand receivers (the error estimate, `eye/estimate.rs`) the
    /// build is most of the cost.
    pub fn build_fast(tris: Vec<[Vec3; 3]>) -> Bvh {
        Bvh::build_to(tris, None)
    }

    /// SAH splits in the top `sah_depth` levels, median splits below; with
    /// no depth, splits at the highest differing bit of the Morton codes.
    fn build_to(tris: Vec<[Vec3; 3]>, sah_depth: Option<usize>) -> Bvh {
        let mut tris: Vec<([Vec3; 3], u32)> = tris
            .into_iter()
            .enumerate()
            .map(|(k, t)| (t, k as u32))
            .collect();
        let codes = sah_depth.is_none().then(|| morton_order(&mut tris));
        // A cancelled call's build ends at the next parallel node
        // (`crate::cancel`): a leaf over what is left, a tree no one traces.
        let stop = crate::cancel::current();
        let nodes = subtree(&mut tris, codes.as_deref(), 0, 0, sah_depth, &stop);
        let (tris, order): (Vec<[Vec3; 3]>, Vec<u32>) = tris.into_iter().unzip();
        let (wide, wide_parent, wide_source) = collapse(&nodes);
        Bvh {
            nodes,
            tris,
            order,
            wide,
            wide_parent,
            wide_source,
            derived: Derived::default(),
        }
    }

    /// The `T` derived from this tree's shape, `make` run on first use (a
    /// cell holding another type is not replaced: `make`'s is returned
    /// uncached).
    pub(crate) fn derived<T: std::any::Any + Send + Sync>(
        &self,
        make: impl Fn() -> T,
    ) -> std::sync::Arc<T> {
        let any = self
            .derived
            .get_or_init(|| std::sync::Arc::new(make()))
            .clone();
        any.downcast::<T>()
            .unwrap_or_else(|_| std::sync::Arc::new(make()))
    }

    /// Levels from the root to the deepest leaf (1 for a single leaf).
    #[cfg(test)]
    fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut work = vec![(0usize, 1usize)];
        while let Some((n, d)) = work.pop() {
            deepest = deepest.max(d);
            let node = self.nodes[n];
            if node.count == 0 && !self.tris.is_empty() {
                work.push((node.start as usize, d + 1));
                work.push((node.start as usize + 1, d + 1));
            }
        }
        deepest
    }

    /// The triangles in BVH order (a leaf's `start..start + count`).
    #[inline(always)]
    pub(crate) fn triangles(&self) -> &[[Vec3; 3]] {
        &self.tris
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The triangles in BVH order, each as its corners' nine coordinates
    /// (v0 x, y, z, v1 x, ...), for the SIMD lanes' loads.
    #[inline(always)]
    pub(crate) fn corner_words(&self) -> &[[f32; 9]] {
        const _: () =
            assert!(std::mem::size_of::<[Vec3; 3]>() == 36 && std::mem::align_of::<Vec3>() == 4);
        // SAFETY: glam's Vec3 is three f32s, repr(C) (size and alignment
        // checked above), so [Vec3; 3] has [f32; 9]'s layout.
        unsafe { std::slice::from_raw_parts(self.tris.as_ptr().cast(), self.tris.len()) }
    }

    /// The nearest hit of the ray o + t d, t in (0, t1): its t and the
    /// triangle's index in the input. Children are visited nearer first, so
    /// a hit found early prunes the farther subtrees.
    pub fn nearest(&self, o: Vec3, d: Vec3, t1: f32) -> Option<(f32, u32)> {
        if self.tris.is_empty() {
            return None;
        }
        let inv = d.recip();
        let sh = Shear::of(d);
        let entry = |n: &Node, best: f32| {
            let a = (n.min - o) * inv;
            let b = (n.max - o) * inv;
            let tmin = a.min(b).max_element().max(0.0);
            let tmax = (a.max(b).min_element() * EXIT_SLACK).min(best);
            (tmin <= tmax).then_some(tmin)
        };
        let mut best = t1;
        let mut hit = None;
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if entry(node, best).is_none() {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                for (k, t) in self.tris[s..s + node.count as usize].iter().enumerate() {
                    if let Some(th) = hit_t(t, o, &sh) {
                        if th > 0.0 && th < best {
                            best = th;
                            hit = Some(s + k);
                        }
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let (el, er) = (
                    entry(&self.nodes[l as usize], best),
                    entry(&self.nodes[r as usize], best),
                );
                // Push the farther child first so the nearer one pops next.
                let order = match (el, er) {
                    (Some(a), Some(b)) if b < a => [Some(l), Some(r)],
                    _ => [er.and(Some(r)), el.and(Some(l))],
                };
                for c in order.into_iter().flatten() {
                    debug_assert!(sp < stack.len());
                    stack[sp] = c;
                    sp += 1;
                }
            }
        }
        hit.map(|k| (best, self.order[k]))
    }

    /// Whether the segment o + t d, t in (t0, t1), crosses node `n`'s box
    /// (the slab test; NaN from 0 * inf compares false and keeps the node),
    /// its exit widened by `EXIT_SLACK`.
    #[inline]
    fn enters(&self, n: &Node, o: Vec3, inv: Vec3, t0: f32, t1: f32) -> bool {
        let a = (n.min - o) * inv;
        let b = (n.max - o) * inv;
        let tmin = a.min(b).max_element().max(t0);
        let tmax = (a.max(b).min_element() * EXIT_SLACK).min(t1);
        tmin <= tmax
    }

    /// The wide node `levels` above wide node `k` (or the root).
    pub(crate) fn wide_ancestor(&self, mut k: u32, levels: u32) -> u32 {
        for _ in 0..levels {
            k = self.wide_parent[k as usize];
        }
        k
    }

    /// Whether the segment o + t d, t in (t0, t1), hits a triangle of the
    /// subtree at node `root`; the leaf that it hits in (for the caller's
    /// cache). With `root` 0, the whole tree.
    pub(crate) fn occluding_leaf(
        &self,
        root: u32,
        o: Vec3,
        d: Vec3,
        t0: f32,
        t1: f32,
    ) -> Option<u32> {
        if self.tris.is_empty() {
            return None;
        }
        let inv = d.recip();
        let sh = Shear::of(d);
        let mut stack = [0u32; 64];
        stack[0] = root;
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let k = stack[sp];
            let node = &self.nodes[k as usize];
            if !self.enters(node, o, inv, t0, t1) {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                if self.tris[s..s + node.count as usize]
                    .iter()
                    .any(|t| hit_t(t, o, &sh).is_some_and(|t| t > t0 && t < t1))
                {
                    return Some(k);
                }
            } else {
                // The build bounds the depth (SAH_DEPTH + 32 < 64) and the
                // stack holds at most one pending sibling per level.
                debug_assert!(sp + 2 <= stack.len());
                stack[sp] = node.start;
                stack[sp + 1] = node.start + 1;
                sp += 2;
            }
        }
        None
    }

    /// Whether the segment o + t d, t in (t0, t1), hits any triangle: one
    /// ray through the whole tree, as the GPU twin (`gpu/exact.wgsl`'s
    /// `occluded`) traces it; the answer every lane of `packet.rs` gets.
    pub fn occluded(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> bool {
        self.occluding_leaf(0, o, d, t0, t1).is_some()
    }
}

/// A triangle with its input index, as the build moves them.
type Slot = ([Vec3; 3], u32);

/// Nodes over more triangles than this build their two children's
/// subtrees in parallel (`rayon::join`); smaller ones are built by one
/// thread. Each split reads its own slice only, so the tree (and the
/// triangles' order) is the one a single thread builds, whatever the
/// threads; only the nodes' numbering differs, which no traversal reads
/// (children are visited through `start`, left then right). Built by one
/// thread, a 2 000 000-triangle mesh took 1.7 s an `exact` call on 2 cores
/// (docs/benchmarks/scale.md).
const PARALLEL_TRIS: usize = 16_384;

/// The split of the node over `slice` at `depth` (more than `LEAF`
/// triangles): the left child's count, after reordering the slice.
fn split(
    slice: &mut [Slot],
    codes: Option<&[u64]>,
    depth: usize,
    sah_depth: Option<usize>,
) -> usize {
    let c = slice.len();
    let mid = match (codes, sah_depth) {
        // Median splits below SAH_DEPTH keep the depth bounded
        // (they reorder within a node; its codes are not read again).
        (Some(codes), _) if depth < SAH_DEPTH => morton_split(codes),
        (None, Some(d)) if depth < d => match sah_split(slice) {
            Some((axis, plane)) => partition(slice, |t| centroid(&t.0)[axis] < plane),
            None => 0,
        },
        _ => 0,
    };
    // No SAH plane, or one that (by rounding at a bin edge) put
    // everything on one side: the median on the longest axis.
    if mid == 0 || mid == c {
        median_split(slice)
    } else {
        mid
    }
}

fn node_over(tris: &[Slot], start: usize) -> Node {
    let (lo, hi) = bounds(tris.iter().map(|t| &t.0));
    Node {
        min: lo,
        max: hi,
        start: start as u32,
        count: tris.len() as u32,
    }
}

/// The nodes of the subtree over `tris` (the triangles from `base` on, the
/// root at `depth`): the root first; an internal node's `start` is its
/// left child's index in the list (the right one follows it), a leaf's is
/// its first triangle's index in the whole tree.
fn subtree(
    tris: &mut [Slot],
    codes: Option<&[u64]>,
    base: usize,
    depth: usize,
    sah_depth: Option<usize>,
    stop: &crate::cancel::Token,
) -> Vec<Node> {
    if tris.len() <= PARALLEL_TRIS {
        return serial_subtree(tris, codes, base, depth, sah_depth);
    }
    if stop.is_cancelled() {
        return vec![node_over(tris, base)];
    }
    let root = node_over(tris, base);
    let mid = split(tris, codes, depth, sah_depth);
    let (lt, rt) = tris.split_at_mut(mid);
    let (lc, rc) = match codes {
        Some(c) => {
            let (a, b) = c.split_at(mid);
            (Some(a), Some(b))
        }
        None => (None, None),
    };
    let (lv, rv) = rayon::join(
        || subtree(lt, lc, base, depth + 1, sah_depth, stop),
        || subtree(rt, rc, base + mid, depth + 1, sah_depth, stop),
    );
    // [root, left, right, left's descendants, right's descendants].
    let (l_at, r_at) = (3, 3 + lv.len() - 1);
    let moved = |n: Node, at: usize| {
        if n.count == 0 {
            Node {
                start: (at + n.start as usize - 1) as u32,
                ..n
            }
        } else {
            n
        }
    };
    let mut out = Vec::with_capacity(1 + lv.len() + rv.len());
    out.push(Node {
        start: 1,
        count: 0,
        ..root
    });
    out.push(moved(lv[0], l_at));
    out.push(moved(rv[0], r_at));
    out.extend(lv[1..].iter().map(|&n| moved(n, l_at)));
    out.extend(rv[1..].iter().map(|&n| moved(n, r_at)));
    out
}

/// `subtree` by one thread: a work list of (node, depth).
fn serial_subtree(
    tris: &mut [Slot],
    codes: Option<&[u64]>,
    base: usize,
    depth: usize,
    sah_depth: Option<usize>,
) -> Vec<Node> {
    let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
    nodes.push(node_over(tris, 0));
    let mut work = vec![(0usize, depth)];
    while let Some((n, depth)) = work.pop() {
        let Node { start, count, .. } = nodes[n];
        let (s, c) = (start as usize, count as usize);
        if c <= LEAF {
            continue;
        }
        let mid = split(
            &mut tris[s..s + c],
            codes.map(|k| &k[s..s + c]),
            depth,
            sah_depth,
        );
        let left = nodes.len();
        nodes.push(node_over(&tris[s..s + mid], s));
        nodes.push(node_over(&tris[s + mid..s + c], s + mid));
        nodes[n].start = left as u32;
        nodes[n].count = 0;
        work.push((left, depth + 1));
        work.push((left + 1, depth + 1));
    }
    // Leaves' triangles by their place in the whole tree.
    for n in nodes.iter_mut().filter(|n| n.count > 0) {
        n.start += base as u32;
    }
    nodes
}

/// Moves the elements for which `left` holds to the front; their count.
fn partition<T>(v: &mut [T], left: impl Fn(&T) -> bool) -> usize {
    let mut k = 0;
    for j in 0..v.len() {
        if left(&v[j]) {
            v.swap(k, j);
            k += 1;
        }
    }
    k
}

/// Splits at the median centroid on the longest axis of the centroids'
/// bounds; the left half's count.
/// Sorts the triangles along the Morton curve of their centroids (21 bits
/// an axis in the centroids' bounds) and returns their codes in that order.
fn morton_order(tris: &mut Vec<([Vec3; 3], u32)>) -> Vec<u64> {
    use rayon::prelude::*;
    let (lo, hi) = centroid_bounds(tris);
    let scale = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE)).recip() * 2_097_151.0;
    // Spreads the low 21 bits of x to every third bit.
    let spread = |x: u64| {
        let mut x = x & 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    };
    let mut keyed: Vec<(u64, ([Vec3; 3], u32))> = tris
        .par_iter()
        .map(|t| {
            let q = ((centroid(&t.0) - lo) * scale).max(Vec3::ZERO);
            let code = spread(q.x as u64) << 2 | spread(q.y as u64) << 1 | spread(q.z as u64);
            (code, *t)
        })
        .collect();
    // Ties keep the input order: the same tree on every run.
    keyed.par_sort_unstable_by_key(|(code, t)| (*code, t.1));
    let codes = keyed.iter().map(|k| k.0).collect();
    *tris = keyed.into_iter().map(|k| k.1).collect();
    codes
}

/// Where sorted Morton `codes` split: the first code with the highest bit
/// in which the first and last differ; 0 when they are all equal (the
/// caller then halves the range).
fn morton_split(codes: &[u64]) -> usize {
    let (first, last) = (codes[0], codes[codes.len() - 1]);
    if first == last {
        return 0;
    }
    let bit = 63 - (first ^ last).leading_zeros();
    codes.partition_point(|c| c >> bit & 1 == 0)
}

fn median_split(slice: &mut [([Vec3; 3], u32)]) -> usize {
    let (clo, chi) = centroid_bounds(slice);
    let ext = chi - clo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = slice.len() / 2;
    slice.select_nth_unstable_by(mid, |a, b| {
        centroid(&a.0)[axis].total_cmp(&centroid(&b.0)[axis])
    });
    mid
}

/// Any crossing of the segment o + t d, t in (t0, t1), with the triangle
/// (`hit_t`).
#[inline]
#[cfg(test)]
pub(crate) fn hits(tri: &[Vec3; 3], o: Vec3, d: Vec3, t0: f32, t1: f32) -> bool {
    hit_t(tri, o, &Shear::of(d)).is_some_and(|t| t > t0 && t < t1)
}

/// A ray's frame for the watertight test (`hit_t`): its direction's
/// largest axis kz (the first of equals) and the next two, kx and ky, and
/// the shear that takes d to the kz axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shear {
    pub k: [usize; 3],
    pub s: [f32; 3],
}

impl Shear {
    /// kx, ky, kz for the largest axis kz (faces are not culled, so the
    /// frame need not keep their winding: no swap where d_kz < 0).
    #[inline(always)]
    pub(crate) const fn axes(kz: usize) -> [usize; 3] {
        [(kz + 1) % 3, (kz + 2) % 3, kz]
    }

    #[inline]
    pub(crate) fn of(d: Vec3) -> Shear {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let [kx, ky, kz] = Shear::axes(kz);
        Shear {
            k: [kx, ky, kz],
            s: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
        }
    }
}

/// Where the line o + t d (its shear `sh`) crosses the triangle, edges
/// included: its t, or None. Watertight (Woop, Benthin & Wald 2013,
/// "Watertight ray/triangle intersection", JCGT 2(1)): each corner is
/// moved to the ray's frame (o at the origin, d along kz, sheared to it)
/// once, and each edge's side of the ray is the 2D cross product of its
/// two ends' (x, y) there, which a triangle sharing the edge computes from
/// the same two values (negated, exactly, where it lists them the other
/// way round). So a line through a shared edge lies on one side for both
/// triangles, or on the edge for both (a hit for both, edges counting),
/// and no rounding lets it slip between them. A line through a shared
/// corner sees the corner at one point near the origin, and each edge
/// around it is again one number that both its triangles share (no such
/// ray slipped in the test below; the paper argues the corner case in
/// full). Faces are not culled: the
/// three sides agree in sign, either sign.
///
/// Möller-Trumbore (the test before) decided each edge from its triangle's
/// own first corner and edge vectors: on a jittered grid, 363 of 9 449
/// rays aimed at shared corners (1 in 26), and 13 of 30 000 at shared
/// edges (1 in 2 300), found neither
/// triangle (the test `no_ray_slips_between_triangles_that_share_an_edge`).
///
/// Every operation is one f32 operation in the order written, which the
/// SIMD lanes (`packet.rs`) and the GPU (`gpu/exact.wgsl`) repeat: the
/// same bits on every path.
#[inline]
pub(crate) fn hit_t(tri: &[Vec3; 3], o: Vec3, sh: &Shear) -> Option<f32> {
    let [kx, ky, kz] = sh.k;
    let [sx, sy, sz] = sh.s;
    // The corners in the ray's frame: (x, y) sheared, z scaled below.
    let rel = tri.map(|v| v - o);
    let xy = rel.map(|a| (a[kx] - sx * a[kz], a[ky] - sy * a[kz]));
    let [(ax, ay), (bx, by), (cx, cy)] = xy;
    // Twice the signed areas of (o, b, c), (o, c, a), (o, a, b).
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let neg = u < 0.0 || v < 0.0 || w < 0.0;
    let pos = u > 0.0 || v > 0.0 || w > 0.0;
    if neg && pos {
        return None;
    }
    // u + v + w is the triangle's projected area (twice); 0 (the ray in its
    // plane, or a degenerate triangle), NaN or inf: no crossing.
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let [az, bz, cz] = rel.map(|a| sz * a[kz]);
    let t = u * az + v * bz + w * cz;
    Some(t / det)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A deterministic uniform in [0, 1).
    pub(crate) fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The nodes in traversal order (root, then each internal node's left
    /// subtree before its right), with their triangles: what any traversal
    /// reads of a tree, whatever its numbering.
    fn canonical(b: &Bvh) -> Vec<(Vec3, Vec3, Vec<u32>)> {
        let mut out = vec![];
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            let n = b.nodes[k];
            let tris = if n.count > 0 {
                b.order[n.start as usize..(n.start + n.count) as usize].to_vec()
            } else {
                stack.push(n.start as usize + 1);
                stack.push(n.start as usize);
                vec![]
            };
            out.push((n.min, n.max, tris));
        }
        out
    }

    #[test]
    fn threads_build_the_tree_one_thread_builds() {
        // Over PARALLEL_TRIS: the top splits run in parallel. Both builds.
        let tris = random_tris(3 * PARALLEL_TRIS + 77, 5);
        for sah in [Some(SAH_DEPTH), None] {
            let par = Bvh::build_to(tris.clone(), sah);
            let mut slots: Vec<Slot> = tris.iter().copied().zip(0..).collect();
            let codes = sah.is_none().then(|| morton_order(&mut slots));
            let nodes = serial_subtree(&mut slots, codes.as_deref(), 0, 0, sah);
            let one = Bvh {
                nodes,
                tris: vec![],
                order: slots.iter().map(|s| s.1).collect(),
                wide: vec![],
                wide_parent: vec![],
                wide_source: vec![],
                derived: Derived::default(),
            };
            assert_eq!(par.order, one.order);
            assert_eq!(canonical(&par), canonical(&one));
            assert!(par.depth() < 64);
        }
    }

    pub(crate) fn random_tris(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
        let mut r = rng(seed);
        (0..n)
            .map(|_| {
                let c = Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 1.0 + r() * 2.0);
                [
                    c,
                    c + Vec3::new(r() * 0.3, r() * 0.1, r() * 0.1),
                    c + Vec3::new(r() * 0.1, r() * 0.3, r() * 0.1),
                ]
            })
            .collect()
    }

    #[test]
    fn any_hit_agrees_with_brute_force() {
        let tris = random_tris(500, 1);
        for bvh in [Bvh::build(tris.clone()), Bvh::build_fast(tris.clone())] {
            let mut r = rng(2);
            for _ in 0..2000 {
                let o = Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 4.0);
                let d = Vec3::new(r() - 0.5, r() - 0.5, 0.0) - o;
                let brute = tris.iter().any(|t| hits(t, o, d, 1e-5, 1.0 - 1e-5));
                assert_eq!(bvh.occluded(o, d, 1e-5, 1.0 - 1e-5), brute);
            }
        }
    }

    /// A jittered grid of `n` x `n` corners far from the origin, each cell
    /// cut along a random diagonal: every inner edge is shared by two
    /// triangles, and the two store its ends in opposite orders or the same
    /// one (flipped faces), as meshes do.
    pub(crate) fn jittered_grid(
        n: usize,
        seed: u64,
    ) -> (Vec<[Vec3; 3]>, Vec<Vec3>, Vec<[usize; 2]>) {
        let mut r = rng(seed);
        let base = Vec3::new(1234.567, -987.65, 321.0);
        let v: Vec<Vec3> = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f32, (k / n) as f32);
                base + Vec3::new(i + 0.4 * r() - 0.2, j + 0.4 * r() - 0.2, 0.3 * r())
            })
            .collect();
        let (mut tris, mut inner) = (vec![], vec![]);
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let [a, b, c, d] = [
                    j * n + i,
                    j * n + i + 1,
                    (j + 1) * n + i,
                    (j + 1) * n + i + 1,
                ];
                let (t1, t2, diag) = if r() < 0.5 {
                    ([a, b, d], [a, d, c], [a, d])
                } else {
                    ([a, b, c], [b, d, c], [b, c])
                };
                // Some faces flipped: a shared edge's ends in either order.
                let flip = |t: [usize; 3], f: bool| if f { [t[0], t[2], t[1]] } else { t };
                tris.push(flip(t1, r() < 0.3).map(|k| v[k]));
                tris.push(flip(t2, r() < 0.3).map(|k| v[k]));
                inner.push(diag);
                if i > 0 {
                    inner.push([a, c]);
                }
                if j > 0 {
                    inner.push([a, b]);
                }
            }
        }
        (tris, v, inner)
    }

    #[test]
    fn no_ray_slips_between_triangles_that_share_an_edge() {
        // Rays from above through points on inner edges (within rounding:
        // the point is rounded to f32) and through inner corners. Möller-
        // Trumbore let 376 of these 39 449 through (363 through corners),
        // and the tree without `EXIT_SLACK` 21 more.
        let n = 24;
        let (tris, v, inner) = jittered_grid(n, 11);
        let bvh = Bvh::build(tris.clone());
        let mut r = rng(12);
        let mut slips = 0;
        let mut rays = 0;
        for k in 0..40_000 {
            let [a, b] = inner[k % inner.len()];
            // Every fourth ray through a corner (s = 0) of an inner edge.
            let s = if k % 4 == 0 { 0.0 } else { r() };
            let p = v[a] + (v[b] - v[a]) * s;
            let (i, j) = (a % n, a / n);
            let corner_inner = i > 0 && i < n - 1 && j > 0 && j < n - 1;
            if s == 0.0 && !corner_inner {
                continue;
            }
            let o = p + Vec3::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0, 2.0 + r() * 5.0);
            let d = (p - o) * 2.0;
            rays += 1;
            // By the triangle test alone, through the tree (any hit and
            // nearest: `EXIT_SLACK` keeps the boxes from culling it).
            let any = tris.iter().any(|t| hits(t, o, d, 0.0, 1.0));
            slips += usize::from(!any);
            slips += usize::from(!bvh.occluded(o, d, 0.0, 1.0));
            slips += usize::from(bvh.nearest(o, d, 1.0).is_none());
        }
        assert!(rays > 30_000);
        assert_eq!(slips, 0, "{slips} of {rays} rays slipped through");
    }

    #[test]
    fn nearest_agrees_with_brute_force() {
        let tris = random_tris(300, 3);
        let bvh = Bvh::build(tris.clone());
        let mut r = rng(4);
        for _ in 0..1000 {
            let o = Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 4.0);
            let d = Vec3::new(r() - 0.5, r() - 0.5, -1.0);
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(k, t)| {
                    hit_t(t, o, &Shear::of(d))
                        .filter(|&th| th > 0.0)
                        .map(|th| (th, k as u32))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            assert_eq!(bvh.nearest(o, d, f32::INFINITY), brute);
        }
    }

    #[test]
    fn every_triangle_lands_in_one_leaf_of_at_most_leaf_size() {
        for build in [Bvh::build, Bvh::build_fast] {
            let bvh = build(random_tris(1000, 5));
            let mut seen = vec![0u32; 1000];
            for n in bvh.nodes.iter().filter(|n| n.count > 0) {
                assert!(n.count as usize <= LEAF);
                for k in n.start..n.start + n.count {
                    seen[bvh.order[k as usize] as usize] += 1;
                }
            }
            assert!(seen.iter().all(|&c| c == 1));
        }
    }

    #[test]
    fn depth_stays_within_the_traversal_stacks() {
        // Identical triangles (no plane separates them) and a geometric
        // progression (SAH peels one triangle a level): both must stay
        // under the 64-entry stacks, with SAH or Morton splits.
        let same = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 5000];
        assert!(Bvh::build(same.clone()).depth() <= 32);
        assert!(Bvh::build_fast(same).depth() <= 32);
        let chain: Vec<[Vec3; 3]> = (0..3000)
            .map(|k| {
                let x = 1.5f32.powi(k / 50);
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1.0, 0.0),
                    Vec3::new(x, 0.0, 1.0),
                ]
            })
            .collect();
        for d in [
            Bvh::build(chain.clone()).depth(),
            Bvh::build_fast(chain).depth(),
        ] {
            assert!(d <= SAH_DEPTH + 32, "depth {d}");
        }
    }

    #[test]
    fn sah_beats_the_median_on_clustered_triangles() {
        // Two clusters far apart, of 100 and 300 triangles: SAH separates
        // them at the root; the median (200 a side) would cut the larger.
        let mut tris = random_tris(400, 6);
        for t in tris.iter_mut().skip(100) {
            for v in t.iter_mut() {
                v.x += 20.0;
            }
        }
        let bvh = Bvh::build(tris);
        let root = bvh.nodes[0];
        let (l, r) = (
            bvh.nodes[root.start as usize],
            bvh.nodes[root.start as usize + 1],
        );
        assert!(l.max.x < 10.0 || l.min.x > 10.0);
        assert!(r.max.x < 10.0 || r.min.x > 10.0);
    }
}
