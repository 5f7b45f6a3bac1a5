//! A spike for issue 51: one ray at a time through an 8-wide BVH, the eight
//! child boxes of a node tested in one AVX2 pass (Embree's layout: each
//! node's boxes in structure-of-arrays form; Wald et al. 2014), leaves of
//! up to four triangles in structure-of-arrays form tested together with
//! SSE, any-hit: the first triangle hit ends the ray.
//!
//! Build: a binned SAH binary tree (16 bins a node, at most 4 triangles a
//! leaf), collapsed to eight-wide nodes by opening, at each node, the
//! child of largest surface area until eight children or only leaves are
//! left (Wald et al. 2008). The triangle test is `moller_trumbore`'s
//! operations lane by lane (no fused multiply-add), so every ray gets the
//! same answer as the scalar test on the same triangles.

use crate::{T0, T1};
use glam::Vec3;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// Leaf flag in a child slot: the low bits are the first leaf block, the
/// count of blocks sits in bits 27..30.
const LEAF: u32 = 1 << 31;
const EMPTY: u32 = u32::MAX;
const MAX_LEAF: usize = 4;
const BINS: usize = 16;
const ORDERED: bool = false;

/// Eight child boxes by axis, then the children.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Node8 {
    lo: [[f32; 8]; 3],
    hi: [[f32; 8]; 3],
    child: [u32; 8],
}

/// Up to four triangles: corner 0 and the two edges from it, by lane.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Tri4 {
    v0: [[f32; 4]; 3],
    e1: [[f32; 4]; 3],
    e2: [[f32; 4]; 3],
}

pub struct Wide8 {
    nodes: Vec<Node8>,
    tris: Vec<Tri4>,
    /// The root: a node, or a leaf where the scene is one leaf.
    root: u32,
}

#[derive(Clone, Copy)]
struct Bin {
    lo: Vec3,
    hi: Vec3,
}

impl Bin {
    fn empty() -> Bin {
        Bin {
            lo: Vec3::splat(f32::INFINITY),
            hi: Vec3::splat(f32::NEG_INFINITY),
        }
    }
    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }
    fn area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A binary node while building.
struct BNode {
    bound: Bin,
    /// Inner: the two children; leaf: the triangle range.
    kids: Option<[usize; 2]>,
    range: (usize, usize),
}

fn build_binary(tris: &[[Vec3; 3]]) -> (Vec<BNode>, Vec<u32>) {
    let lo: Vec<Vec3> = tris.iter().map(|t| t[0].min(t[1]).min(t[2])).collect();
    let hi: Vec<Vec3> = tris.iter().map(|t| t[0].max(t[1]).max(t[2])).collect();
    let c: Vec<Vec3> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (*a + *b)).collect();
    let mut idx: Vec<u32> = (0..tris.len() as u32).collect();
    let mut nodes = vec![];
    fn rec(
        nodes: &mut Vec<BNode>,
        idx: &mut [u32],
        off: usize,
        lo: &[Vec3],
        hi: &[Vec3],
        c: &[Vec3],
    ) -> usize {
        let mut b = Bin::empty();
        let mut cb = Bin::empty();
        for &i in idx.iter() {
            b.grow(lo[i as usize], hi[i as usize]);
            cb.grow(c[i as usize], c[i as usize]);
        }
        let me = nodes.len();
        nodes.push(BNode {
            bound: b,
            kids: None,
            range: (off, off + idx.len()),
        });
        if idx.len() <= MAX_LEAF {
            return me;
        }
        // Binned SAH over the centroids' widest axis.
        let ext = cb.hi - cb.lo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let (a0, w) = (cb.lo[axis], ext[axis]);
        let mut split = idx.len() / 2;
        if w > 0.0 {
            let bin_of = |i: u32| (((c[i as usize][axis] - a0) / w * BINS as f32) as usize).min(BINS - 1);
            let mut bins = [Bin::empty(); BINS];
            let mut counts = [0usize; BINS];
            for &i in idx.iter() {
                let k = bin_of(i);
                bins[k].grow(lo[i as usize], hi[i as usize]);
                counts[k] += 1;
            }
            let mut right = [(0f32, 0usize); BINS];
            let (mut acc, mut n) = (Bin::empty(), 0);
            for k in (1..BINS).rev() {
                acc.grow(bins[k].lo, bins[k].hi);
                n += counts[k];
                right[k] = (acc.area(), n);
            }
            let (mut acc, mut n) = (Bin::empty(), 0);
            let mut best = (f32::INFINITY, 0usize);
            for k in 1..BINS {
                acc.grow(bins[k - 1].lo, bins[k - 1].hi);
                n += counts[k - 1];
                let (ra, rn) = right[k];
                if n == 0 || rn == 0 {
                    continue;
                }
                let cost = acc.area() * n as f32 + ra * rn as f32;
                if cost < best.0 {
                    best = (cost, k);
                }
            }
            let leaf_cost = b.area() * idx.len() as f32;
            if best.0.is_finite() && (best.0 < leaf_cost || idx.len() > 4 * MAX_LEAF) {
                // Partition by bin.
                let (mut l, mut r) = (0, idx.len());
                while l < r {
                    if bin_of(idx[l]) < best.1 {
                        l += 1;
                    } else {
                        r -= 1;
                        idx.swap(l, r);
                    }
                }
                split = l;
            } else if best.0.is_finite() {
                return me;
            }
        }
        if split == 0 || split == idx.len() {
            idx.sort_by(|&p, &q| c[p as usize][axis].total_cmp(&c[q as usize][axis]));
            split = idx.len() / 2;
        }
        let (left, right) = idx.split_at_mut(split);
        let l = rec(nodes, left, off, lo, hi, c);
        let r = rec(nodes, right, off + split, lo, hi, c);
        nodes[me].kids = Some([l, r]);
        me
    }
    if !tris.is_empty() {
        rec(&mut nodes, &mut idx, 0, &lo, &hi, &c);
    }
    (nodes, idx)
}

impl Wide8 {
    pub fn new(tris: &[[Vec3; 3]]) -> Wide8 {
        let (bn, idx) = build_binary(tris);
        let mut w = Wide8 {
            nodes: vec![],
            tris: vec![],
            root: EMPTY,
        };
        if bn.is_empty() {
            return w;
        }
        w.root = w.emit(&bn, 0, tris, &idx);
        w
    }

    /// The slot value of binary node `b`: a leaf's blocks, or a wide node.
    fn emit(&mut self, bn: &[BNode], b: usize, tris: &[[Vec3; 3]], idx: &[u32]) -> u32 {
        let n = &bn[b];
        let Some(kids) = n.kids else {
            let first = self.tris.len();
            let ids = &idx[n.range.0..n.range.1];
            for chunk in ids.chunks(4) {
                let mut t = Tri4 {
                    v0: [[0.0; 4]; 3],
                    e1: [[0.0; 4]; 3],
                    e2: [[0.0; 4]; 3],
                };
                // Padding lanes: a degenerate triangle (det = 0: no hit).
                for (l, &i) in chunk.iter().enumerate() {
                    let tri = tris[i as usize];
                    let (e1, e2) = (tri[1] - tri[0], tri[2] - tri[0]);
                    for a in 0..3 {
                        t.v0[a][l] = tri[0][a];
                        t.e1[a][l] = e1[a];
                        t.e2[a][l] = e2[a];
                    }
                }
                self.tris.push(t);
            }
            let blocks = (self.tris.len() - first) as u32;
            assert!(blocks < 16 && first < (1 << 27));
            return LEAF | (blocks << 27) | first as u32;
        };
        // Open the largest inner child until eight or only leaves.
        let mut open: Vec<usize> = kids.to_vec();
        while open.len() < 8 {
            let Some((k, _)) = open
                .iter()
                .enumerate()
                .filter(|(_, &c)| bn[c].kids.is_some())
                .max_by(|a, b| bn[*a.1].bound.area().total_cmp(&bn[*b.1].bound.area()))
            else {
                break;
            };
            let c = open.swap_remove(k);
            open.extend(bn[c].kids.unwrap());
        }
        let me = self.nodes.len();
        self.nodes.push(Node8 {
            lo: [[f32::INFINITY; 8]; 3],
            hi: [[f32::NEG_INFINITY; 8]; 3],
            child: [EMPTY; 8],
        });
        for (s, &c) in open.iter().enumerate() {
            let v = self.emit(bn, c, tris, idx);
            let node = &mut self.nodes[me];
            node.child[s] = v;
            // Widened by a few ulps of the scene's scale: the slab test's
            // rounding (lo * inv - o * inv) never drops a ray that touches
            // a triangle on the box's face.
            let (lo, hi) = (bn[c].bound.lo, bn[c].bound.hi);
            let pad = 4.0 * f32::EPSILON * (1.0 + lo.abs().max(hi.abs()).max_element());
            for a in 0..3 {
                node.lo[a][s] = lo[a] - pad;
                node.hi[a][s] = hi[a] + pad;
            }
        }
        me as u32
    }

    /// Whether a triangle crosses o + t d, t in (T0, T1).
    pub fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        if self.root == EMPTY {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 was detected.
            return unsafe { self.occluded_avx2(o, d) };
        }
        panic!("the spike has no portable path")
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn occluded_avx2(&self, o: Vec3, d: Vec3) -> bool {
        // 1/d with zeros kept finite (a huge slope of the right sign), so
        // that lo * inv - o * inv is never 0 * inf.
        let safe = |x: f32| if x.abs() < 1e-30 { 1e-30f32.copysign(x) } else { x };
        let inv = Vec3::new(1.0 / safe(d.x), 1.0 / safe(d.y), 1.0 / safe(d.z));
        let oi = o * inv;
        // Near and far planes by the direction's sign (Embree): no min/max.
        let near_hi = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        let inv8 = [_mm256_set1_ps(inv.x), _mm256_set1_ps(inv.y), _mm256_set1_ps(inv.z)];
        let oi8 = [_mm256_set1_ps(oi.x), _mm256_set1_ps(oi.y), _mm256_set1_ps(oi.z)];
        let (t0, t1) = (_mm256_set1_ps(T0), _mm256_set1_ps(T1));
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut cur = self.root;
        loop {
            if cur & LEAF != 0 {
                if self.leaf_hits(cur, o, d) {
                    return true;
                }
            } else {
                let n = self.nodes.get_unchecked(cur as usize);
                let mut tn = t0;
                let mut tf = t1;
                for a in 0..3 {
                    let (np, fp) = if near_hi[a] { (&n.hi[a], &n.lo[a]) } else { (&n.lo[a], &n.hi[a]) };
                    let near = _mm256_sub_ps(_mm256_mul_ps(_mm256_load_ps(np.as_ptr()), inv8[a]), oi8[a]);
                    let far = _mm256_sub_ps(_mm256_mul_ps(_mm256_load_ps(fp.as_ptr()), inv8[a]), oi8[a]);
                    tn = _mm256_max_ps(tn, near);
                    tf = _mm256_min_ps(tf, far);
                }
                let mut mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as u32;
                if ORDERED && mask.count_ones() > 1 {
                    // Nearest popped first: push the hits far to near.
                    let mut dist = [0f32; 8];
                    _mm256_storeu_ps(dist.as_mut_ptr(), tn);
                    let mut hit = [(0f32, 0u32); 8];
                    let mut k = 0;
                    while mask != 0 {
                        let s = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        // Insertion, farthest first.
                        let e = (dist[s], n.child[s]);
                        let mut j = k;
                        while j > 0 && hit[j - 1].0 < e.0 {
                            hit[j] = hit[j - 1];
                            j -= 1;
                        }
                        hit[j] = e;
                        k += 1;
                    }
                    for h in &hit[..k] {
                        *stack.get_unchecked_mut(sp) = h.1;
                        sp += 1;
                    }
                } else {
                    while mask != 0 {
                        let s = mask.trailing_zeros() as usize;
                        mask &= mask - 1;
                        *stack.get_unchecked_mut(sp) = n.child[s];
                        sp += 1;
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = *stack.get_unchecked(sp);
        }
    }

    /// Möller–Trumbore on a leaf's blocks, four triangles a pass, the
    /// operations of the scalar test lane by lane.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn leaf_hits(&self, slot: u32, o: Vec3, d: Vec3) -> bool {
        let first = (slot & ((1 << 27) - 1)) as usize;
        let blocks = ((slot >> 27) & 0xF) as usize;
        let (ox, oy, oz) = (_mm_set1_ps(o.x), _mm_set1_ps(o.y), _mm_set1_ps(o.z));
        let (dx, dy, dz) = (_mm_set1_ps(d.x), _mm_set1_ps(d.y), _mm_set1_ps(d.z));
        let zero = _mm_setzero_ps();
        let one = _mm_set1_ps(1.0);
        for t in &self.tris[first..first + blocks] {
            let ld = |a: &[f32; 4]| _mm_load_ps(a.as_ptr());
            let (e1x, e1y, e1z) = (ld(&t.e1[0]), ld(&t.e1[1]), ld(&t.e1[2]));
            let (e2x, e2y, e2z) = (ld(&t.e2[0]), ld(&t.e2[1]), ld(&t.e2[2]));
            // p = d x e2 (glam: y*rz - ry*z, z*rx - rz*x, x*ry - rx*y).
            let px = _mm_sub_ps(_mm_mul_ps(dy, e2z), _mm_mul_ps(e2y, dz));
            let py = _mm_sub_ps(_mm_mul_ps(dz, e2x), _mm_mul_ps(e2z, dx));
            let pz = _mm_sub_ps(_mm_mul_ps(dx, e2y), _mm_mul_ps(e2x, dy));
            let dot = |ax, ay, az, bx, by, bz| {
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz))
            };
            let det = dot(e1x, e1y, e1z, px, py, pz);
            let inv = _mm_div_ps(one, det);
            let sx = _mm_sub_ps(ox, ld(&t.v0[0]));
            let sy = _mm_sub_ps(oy, ld(&t.v0[1]));
            let sz = _mm_sub_ps(oz, ld(&t.v0[2]));
            let u = _mm_mul_ps(dot(sx, sy, sz, px, py, pz), inv);
            // q = s x e1.
            let qx = _mm_sub_ps(_mm_mul_ps(sy, e1z), _mm_mul_ps(e1y, sz));
            let qy = _mm_sub_ps(_mm_mul_ps(sz, e1x), _mm_mul_ps(e1z, sx));
            let qz = _mm_sub_ps(_mm_mul_ps(sx, e1y), _mm_mul_ps(e1x, sy));
            let v = _mm_mul_ps(dot(dx, dy, dz, qx, qy, qz), inv);
            let th = _mm_mul_ps(dot(e2x, e2y, e2z, qx, qy, qz), inv);
            // det != 0 and finite; 0 <= u <= 1; v >= 0; u + v <= 1; T0 < t < T1.
            let finite = _mm_cmp_ps::<_CMP_LT_OQ>(
                _mm_andnot_ps(_mm_set1_ps(-0.0), det),
                _mm_set1_ps(f32::INFINITY),
            );
            let ok = _mm_and_ps(_mm_cmp_ps::<_CMP_NEQ_OQ>(det, zero), finite);
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_GE_OQ>(u, zero));
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_LE_OQ>(u, one));
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_GE_OQ>(v, zero));
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_LE_OQ>(_mm_add_ps(u, v), one));
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_GT_OQ>(th, _mm_set1_ps(T0)));
            let ok = _mm_and_ps(ok, _mm_cmp_ps::<_CMP_LT_OQ>(th, _mm_set1_ps(T1)));
            if _mm_movemask_ps(ok) != 0 {
                return true;
            }
        }
        false
    }
}

impl crate::contenders::Contender for Wide8 {
    const NAME: &'static str = "spike: 8-wide BVH, one ray, AVX2 boxes, SSE 4-triangle leaves";
    const CRATE: Option<&'static str> = None;
    fn build(tris: &[[Vec3; 3]]) -> Self {
        Wide8::new(tris)
    }
    #[inline]
    fn occluded(&self, o: Vec3, d: Vec3) -> bool {
        Wide8::occluded(self, o, d)
    }
}
