//! Exact visibility by ray casting: stratified light samples per receiver,
//! shadow rays against a BVH over the occluder triangles, all cores.
//!
//! Not a soft shadow map: it reads the occluder triangles (not the occluder
//! maps) and the receiver points. It converges to the true visibility as
//! 1/sqrt(samples) (stratified: faster on smooth penumbrae), is deterministic
//! (the jitter is a hash of the receiver's index and the sample's), and is the
//! in-package reference that needs no Mitsuba.
//!
//! Geometry is in light space (relative to the light's center, computed in
//! f64 and then stored in f32), so a scene far from the world origin keeps its
//! precision. The light is the rectangle [-Lx/2, Lx/2] x [-Ly/2, Ly/2] at Z = 0.

use super::{LightPoint, ShadowInputs, ShadowMethod};
use glam::Vec3;
use rayon::prelude::*;

/// The exact method with `samples` light samples per receiver.
pub struct Exact {
    pub samples: u32,
}

/// Triangles per BVH leaf at most.
const LEAF: usize = 4;
/// Shadow rays start this fraction of the way from the receiver and stop this
/// fraction short of the light: occluders touching the receiver or the light
/// are not hit by rounding alone.
pub(crate) const RAY_EPS: f32 = 1e-5;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle; inner: index of the left child (right = left + 1).
    start: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// A bounding volume hierarchy over triangles (median split on the longest
/// axis of the centroids' bounds).
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<[Vec3; 3]>,
    /// The index each triangle had in the input (`nearest` reports it).
    order: Vec<u32>,
}

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
    #[cfg(feature = "gpu")]
    pub(crate) fn order(&self) -> &[u32] {
        &self.order
    }

    pub fn build(tris: Vec<[Vec3; 3]>) -> Bvh {
        let mut tris: Vec<([Vec3; 3], u32)> = tris
            .into_iter()
            .enumerate()
            .map(|(k, t)| (t, k as u32))
            .collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        let (lo, hi) = bounds(tris.iter().map(|t| &t.0));
        nodes.push(Node {
            min: lo,
            max: hi,
            start: 0,
            count: tris.len() as u32,
        });
        // Iterative build: (node index, range) work list.
        let mut work = vec![0usize];
        while let Some(n) = work.pop() {
            let Node { start, count, .. } = nodes[n];
            let (s, c) = (start as usize, count as usize);
            if c <= LEAF {
                continue;
            }
            let slice = &mut tris[s..s + c];
            let (clo, chi) = slice.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(a, b), t| (a.min(centroid(&t.0)), b.max(centroid(&t.0))),
            );
            let ext = chi - clo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = c / 2;
            slice.select_nth_unstable_by(mid, |a, b| {
                centroid(&a.0)[axis].total_cmp(&centroid(&b.0)[axis])
            });
            let left = nodes.len();
            for (off, len) in [(0, mid), (mid, c - mid)] {
                let (lo, hi) = bounds(tris[s + off..s + off + len].iter().map(|t| &t.0));
                nodes.push(Node {
                    min: lo,
                    max: hi,
                    start: (s + off) as u32,
                    count: len as u32,
                });
            }
            nodes[n].start = left as u32;
            nodes[n].count = 0;
            work.push(left);
            work.push(left + 1);
        }
        let (tris, order) = tris.into_iter().unzip();
        Bvh { nodes, tris, order }
    }

    /// The nearest hit of the ray o + t d, t in (0, t1): its t and the
    /// triangle's index in the input. Children are visited nearer first, so
    /// a hit found early prunes the farther subtrees.
    pub fn nearest(&self, o: Vec3, d: Vec3, t1: f32) -> Option<(f32, u32)> {
        if self.tris.is_empty() {
            return None;
        }
        let inv = d.recip();
        let entry = |n: &Node, best: f32| {
            let a = (n.min - o) * inv;
            let b = (n.max - o) * inv;
            let tmin = a.min(b).max_element().max(0.0);
            let tmax = a.max(b).min_element().min(best);
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
                    if let Some(th) = hit_t(t, o, d) {
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

    /// Whether the segment o + t d, t in (t0, t1), hits any triangle.
    fn occluded(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> bool {
        if self.tris.is_empty() {
            return false;
        }
        let inv = d.recip();
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            // Slab test; NaN (0 * inf) compares false and keeps the node.
            let a = (node.min - o) * inv;
            let b = (node.max - o) * inv;
            let tmin = a.min(b).max_element().max(t0);
            let tmax = a.max(b).min_element().min(t1);
            if tmin > tmax {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                for t in &self.tris[s..s + node.count as usize] {
                    if hits(t, o, d, t0, t1) {
                        return true;
                    }
                }
            } else {
                // Median splits halve the triangles at each level, so the tree
                // is at most ~log2(n) deep and the stack holds at most one
                // pending sibling per level: 64 entries cover any u32 count.
                debug_assert!(sp + 2 <= stack.len());
                stack[sp] = node.start;
                stack[sp + 1] = node.start + 1;
                sp += 2;
            }
        }
        false
    }
}

/// Möller-Trumbore, any hit with t in (t0, t1).
#[inline]
fn hits(tri: &[Vec3; 3], o: Vec3, d: Vec3, t0: f32, t1: f32) -> bool {
    hit_t(tri, o, d).is_some_and(|t| t > t0 && t < t1)
}

/// Möller-Trumbore: the line's parameter t where it crosses the triangle
/// (edges included), or None.
#[inline]
fn hit_t(tri: &[Vec3; 3], o: Vec3, d: Vec3) -> Option<f32> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - tri[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}

/// A 32-bit mix (splitmix-style) for deterministic jitter.
#[inline]
fn hash(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

#[inline]
fn unit(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// The fraction of `grid` stratified light samples whose segment is clear:
/// `ray(x, y)` gives, for the light point (x, y, 0), the segment's origin
/// o, its direction d = light point - o, and t0 (the segment is t in (t0,
/// 1 - RAY_EPS)). The jitter is a hash of `key` and the sample.
#[inline]
pub(crate) fn stratified(
    bvh: &Bvh,
    key: u64,
    grid: (u32, u32),
    size: [f32; 2],
    mut ray: impl FnMut(f32, f32) -> (Vec3, Vec3, f32),
) -> f32 {
    let (na, nb) = grid;
    let mut seen = 0u32;
    for sb in 0..nb {
        for sa in 0..na {
            let h = hash(key ^ hash(((sb * na + sa) as u64) << 1));
            let x = ((sa as f32 + unit(h)) / na as f32 - 0.5) * size[0];
            let y = ((sb as f32 + unit(hash(h))) / nb as f32 - 0.5) * size[1];
            let (o, d, t0) = ray(x, y);
            if !bvh.occluded(o, d, t0, 1.0 - RAY_EPS) {
                seen += 1;
            }
        }
    }
    seen as f32 / (na * nb) as f32
}

/// The stratification grid a x b = samples, a the largest divisor <= sqrt,
/// the longer side of the light getting the larger count.
pub fn sample_grid(samples: u32, light_size: [f64; 2]) -> (u32, u32) {
    let mut a = (samples as f64).sqrt() as u32;
    while a > 1 && !samples.is_multiple_of(a) {
        a -= 1;
    }
    let a = a.max(1);
    let b = samples / a;
    if light_size[0] >= light_size[1] {
        (b, a)
    } else {
        (a, b)
    }
}

impl Exact {
    /// Visibility at a receiver at light-space position p (planar depth p.z).
    fn visibility(&self, bvh: &Bvh, p: Vec3, key: u64, grid: (u32, u32), size: [f32; 2]) -> f32 {
        stratified(bvh, key, grid, size, |x, y| {
            (p, Vec3::new(x, y, 0.0) - p, RAY_EPS)
        })
    }

    fn shade(&self, inputs: &ShadowInputs, pts: &[(u64, Option<Vec3>)]) -> Vec<f32> {
        let Some(tris) = inputs.occluder_triangles else {
            // Nothing to occlude with: callers check before (the pipeline
            // refuses exact without meshes), so this is all-lit by definition.
            return vec![1.0; pts.len()];
        };
        let bvh = Bvh::build(tris.to_vec());
        let grid = sample_grid(self.samples, inputs.light_size);
        let size = [inputs.light_size[0] as f32, inputs.light_size[1] as f32];
        pts.par_iter()
            .with_min_len(64)
            .map(|&(key, p)| match p {
                Some(p) => self.visibility(&bvh, p, key, grid, size),
                None => 1.0,
            })
            .collect()
    }
}

fn light_point(p: &LightPoint) -> Option<Vec3> {
    (p.z.is_finite() && p.z > 0.0).then(|| Vec3::new(p.x * p.z, p.y * p.z, p.z))
}

impl ShadowMethod for Exact {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        let g = &inputs.grid;
        let pts: Vec<(u64, Option<Vec3>)> = (0..g.len())
            .map(|k| {
                let p = LightPoint {
                    x: g.x_of(k % g.width) as f32,
                    y: g.y_of(k / g.width) as f32,
                    z: inputs.receiver[k],
                };
                (k as u64, light_point(&p))
            })
            .collect();
        self.shade(inputs, &pts)
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let pts: Vec<(u64, Option<Vec3>)> = points
            .iter()
            .enumerate()
            .map(|(k, p)| (k as u64, light_point(p)))
            .collect();
        self.shade(inputs, &pts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::MapGrid;

    fn plate(z: f32, lo: [f32; 2], hi: [f32; 2]) -> Vec<[Vec3; 3]> {
        let v = [
            Vec3::new(lo[0], lo[1], z),
            Vec3::new(hi[0], lo[1], z),
            Vec3::new(hi[0], hi[1], z),
            Vec3::new(lo[0], hi[1], z),
        ];
        vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut seed = 1u64;
        let mut r = || {
            seed = hash(seed);
            unit(seed)
        };
        let tris: Vec<[Vec3; 3]> = (0..500)
            .map(|_| {
                let c = Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 1.0 + r() * 2.0);
                [
                    c,
                    c + Vec3::new(r() * 0.3, r() * 0.1, r() * 0.1),
                    c + Vec3::new(r() * 0.1, r() * 0.3, r() * 0.1),
                ]
            })
            .collect();
        let bvh = Bvh::build(tris.clone());
        for _ in 0..2000 {
            let o = Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 4.0);
            let d = Vec3::new(r() - 0.5, r() - 0.5, 0.0) - o;
            let brute = tris.iter().any(|t| hits(t, o, d, RAY_EPS, 1.0 - RAY_EPS));
            assert_eq!(bvh.occluded(o, d, RAY_EPS, 1.0 - RAY_EPS), brute);
        }
    }

    #[test]
    fn plate_matches_the_closed_form_within_the_stratified_bound() {
        // Plate tangent [-0.1, 0.15] x [-0.05, 0.2] at depth 2, receivers at depth 4.
        let (zo, zr) = (2.0f64, 4.0f64);
        let tris = plate(
            zo as f32,
            [-0.1 * 2.0, -0.05 * 2.0],
            [0.15 * 2.0, 0.2 * 2.0],
        );
        let n = 24;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let receiver = vec![zr as f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &receiver,
            occluder_layers: vec![],
            occluder_triangles: Some(&tris),
        };
        let samples = 1024;
        let v = Exact { samples }.visibility_map(&inputs);
        let k = zr * zo / (zr - zo);
        let ov = |lo: f64, hi: f64, c: f64| {
            ((k * (hi - c) + 0.5).clamp(0.0, 1.0) - (k * (lo - c) + 0.5).clamp(0.0, 1.0)).max(0.0)
        };
        let mut max = 0f64;
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (grid.x_of(i), grid.y_of(j));
                let exact = 1.0 - ov(-0.1, 0.15, x) * ov(-0.05, 0.2, y);
                max = max.max((v[j * n + i] as f64 - exact).abs());
            }
        }
        // A 32x32 stratification: the shadow's edges cross at most 2 x 32
        // strata per axis, each wrong by at most 1/1024 -> 4 * 32 / 1024.
        assert!(max <= 4.0 * 32.0 / 1024.0, "max error {max}");
    }

    #[test]
    fn deterministic_and_lit_without_occluders() {
        let tris = plate(2.0, [-0.3, -0.3], [0.3, 0.3]);
        let pts = [
            LightPoint {
                x: 0.05,
                y: 0.0,
                z: 4.0,
            },
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: f32::INFINITY,
            },
        ];
        let grid = MapGrid::new(1, 1, [1.0, 1.0]).unwrap();
        let mk = |t| ShadowInputs {
            grid,
            occluder_grid: grid,
            light_size: [1.0, 1.0],
            receiver: &[],
            occluder_layers: vec![],
            occluder_triangles: t,
        };
        let a = Exact { samples: 64 }.visibility_points(&mk(Some(&tris)), &pts);
        let b = Exact { samples: 64 }.visibility_points(&mk(Some(&tris)), &pts);
        assert_eq!(a, b);
        assert!(a[0] < 1.0 && a[1] == 1.0);
        let empty: Vec<[Vec3; 3]> = vec![];
        assert_eq!(
            Exact { samples: 64 }.visibility_points(&mk(Some(&empty)), &pts),
            vec![1.0, 1.0]
        );
    }

    #[test]
    fn sample_grids_are_near_square() {
        assert_eq!(sample_grid(256, [1.0, 1.0]), (16, 16));
        assert_eq!(sample_grid(12, [2.0, 1.0]), (4, 3));
        assert_eq!(sample_grid(7, [1.0, 1.0]), (7, 1));
    }
}
