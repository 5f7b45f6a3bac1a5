//! Eight shadow rays traced together through the BVH, one per lane: the
//! rays of eight neighbouring receivers toward the same stratum of the
//! light (Wald et al. 2001, "Interactive rendering with coherent ray
//! tracing"; packets of neighbouring pixels' rays, here shadow rays).
//!
//! Neighbouring receivers' rays to one stratum start a texel apart and end
//! within a stratum of each other, so they cross the occluders close
//! together and mostly enter the same nodes: a node is fetched once for
//! the eight, and its slab test, like each triangle's, runs on all lanes at
//! once (the lane loops below compile to AVX2 under `simd.rs`-style
//! dispatch: `exact.rs` calls through `traverse`). Where the CPU has
//! AVX-512 (F and DQ), a 512-bit register holds the eight rays twice, so
//! that one instruction tests two of a node's slots, or two triangles
//! (`avx512`): on bench_scale's scenes at 640x480 and 64 samples, 2-10%
//! less time a shadow ray than AVX2 (mesh_125k 23 -> 20-21 ns, mesh_2m
//! 51-53 -> 50-51, many_meshes 28-29 -> 26, crowd 17 -> 16; two
//! interleaved runs each, `SOFTSHADOW_NO_AVX512=1` for the AVX2 path),
//! and 10-20% less again by the medians of four interleaved runs with the
//! pairs built by one permute each (docs/methods/exact.md).
//!
//! Every lane gets the answer its ray alone gets from `Bvh::occluded`:
//! the lane operations are the scalar ones, in the same order (glam's
//! `Vec3::min`/`max` are `a < b ? a : b`, as the lanes' selects are; `f32::
//! min`/`max` against t0 and t1 drop a NaN as the selects with t0 and t1
//! second do), a lane counts a triangle's hit only where its own slab test
//! entered the leaf (which, the slab test being monotone in the box, it
//! does only if it entered every ancestor: `Bvh::leaf_occludes`), and the
//! order in which an any-hit search visits nodes does not change its answer.
//!
//! Children are pushed in slot order, not by distance: ordering them by the
//! entered lanes' nearest entry (two masked reductions and a sort a node,
//! nearest or farthest first) took 10-40% more time a shadow ray on
//! bench_scale's mesh_125k, crowd and many_meshes (two interleaved runs
//! each): the reductions and the sort cost more than the visits they
//! saved (a sorting network in place of `sort_unstable_by` was not tried).

use super::bvh::{Bvh, Shear};
use glam::Vec3;

/// Rays per packet.
pub(crate) const LANES: usize = 8;
/// One bit per lane.
pub(crate) type Mask = u8;
/// Every lane.
pub(crate) const ALL: Mask = Mask::MAX;

type F = [f32; LANES];

/// Eight segments o + t d.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rays {
    o: [F; 3],
    d: [F; 3],
    inv: [F; 3],
    /// Each lane's shear for the watertight test (`bvh::Shear::s`).
    s: [F; 3],
    /// The lanes whose direction's largest axis (`bvh::Shear::k`'s kz) is
    /// x, y, z: a triangle is tested once for each such group that is
    /// open, its corners' coordinates taken in that group's axis order
    /// (neighbouring receivers' rays to one stratum are mostly one group).
    by_axis: [Mask; 3],
}

impl Rays {
    /// The rays from `o[i]` along `d[i]`.
    #[inline(always)]
    pub(crate) fn new(o: [Vec3; LANES], d: [Vec3; LANES]) -> Rays {
        let o = [0, 1, 2].map(|a| o.map(|v| v[a]));
        let d = [0, 1, 2].map(|a| d.map(|v| v[a]));
        // Vec3::recip per lane.
        let inv = d.map(|c| c.map(|x| 1.0 / x));
        let mut s = [[0.0; LANES]; 3];
        let mut by_axis = [0; 3];
        for i in 0..LANES {
            let sh = Shear::of(Vec3::new(d[0][i], d[1][i], d[2][i]));
            for (lane, v) in s.iter_mut().zip(sh.s) {
                lane[i] = v;
            }
            by_axis[sh.k[2]] |= 1 << i;
        }
        Rays {
            o,
            d,
            inv,
            s,
            by_axis,
        }
    }

    fn lane(&self, i: usize) -> (Vec3, Vec3) {
        let v = |c: &[F; 3]| Vec3::new(c[0][i], c[1][i], c[2][i]);
        (v(&self.o), v(&self.d))
    }
}

impl Bvh {
    /// The lanes of `active` whose segment o + t d, t in (t0, t1), hits a
    /// triangle under wide node `from` (0: the whole tree), and the wide
    /// node holding the last leaf that blocked one (for the caller's
    /// shadow cache). Each lane's answer under the root is
    /// `Bvh::occluded`'s for its ray.
    #[inline(always)]
    pub(crate) fn occluded_lanes(
        &self,
        from: u32,
        rays: &Rays,
        active: Mask,
        t0: f32,
        t1: f32,
    ) -> (Mask, Option<u32>) {
        if self.is_empty() || active == 0 {
            return (0, None);
        }
        #[cfg(target_arch = "x86_64")]
        {
            if avx512::available() {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { avx512::occluded(self, from, rays, active, t0, t1) };
            }
            if is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { avx2::occluded(self, from, rays, active, t0, t1) };
            }
        }
        self.occluded_lanes_scalar(rays, active, t0, t1)
    }

    /// `occluded_lanes` without AVX2: one lane at a time through the whole
    /// binary tree, as `Bvh::occluded`, and no cache (searching more than a
    /// subtree finds what it holds too).
    fn occluded_lanes_scalar(
        &self,
        rays: &Rays,
        active: Mask,
        t0: f32,
        t1: f32,
    ) -> (Mask, Option<u32>) {
        let mut blocked = 0;
        for i in 0..LANES {
            let (o, d) = rays.lane(i);
            if active & (1 << i) != 0 && self.occluding_leaf(0, o, d, t0, t1).is_some() {
                blocked |= 1 << i;
            }
        }
        (blocked, None)
    }
}

/// The lanes in AVX2 registers, each operation the scalar one.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Bvh, Mask, Rays};
    use crate::trace::bvh::{Shear, EXIT_SLACK};
    use crate::trace::bvh_wide::Wide;
    use core::arch::x86_64::*;

    struct Lanes {
        o: [__m256; 3],
        inv: [__m256; 3],
        s: [__m256; 3],
        t0: __m256,
        t1: __m256,
    }

    /// The rays in registers.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn lanes(rays: &Rays, t0: f32, t1: f32) -> Lanes {
        // SAFETY: each array is LANES = 8 f32s, an unaligned 256-bit load.
        let load = |a: &[f32; 8]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        Lanes {
            o: rays.o.each_ref().map(load),
            inv: rays.inv.each_ref().map(load),
            s: rays.s.each_ref().map(load),
            t0: _mm256_set1_ps(t0),
            t1: _mm256_set1_ps(t1),
        }
    }

    /// The lanes whose segment enters the box of slot `k` of `w`:
    /// `Bvh::enters` per lane. minps(a, b) is a < b ? a : b and maxps(a,
    /// b) is a > b ? a : b, glam's `Vec3::min`/`max` and the ones of its
    /// `max_element`/`min_element`; maxps(m, t0) keeps t0 for a NaN m as
    /// `f32::max` does (and minps(m, t1) t1); the exit is widened by
    /// `EXIT_SLACK` where the scalar test widens it.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn enter(l: &Lanes, w: &Wide, k: usize) -> i32 {
        let slab = |a: usize| {
            let p = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(w.lo[a][k]), l.o[a]), l.inv[a]);
            let q = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(w.hi[a][k]), l.o[a]), l.inv[a]);
            (_mm256_min_ps(p, q), _mm256_max_ps(p, q))
        };
        let (n0, f0) = slab(0);
        let (n1, f1) = slab(1);
        let (n2, f2) = slab(2);
        let tmin = _mm256_max_ps(_mm256_max_ps(_mm256_max_ps(n0, n1), n2), l.t0);
        let exit = _mm256_min_ps(_mm256_min_ps(f0, f1), f2);
        let tmax = _mm256_min_ps(_mm256_mul_ps(exit, _mm256_set1_ps(EXIT_SLACK)), l.t1);
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax))
    }

    /// The lanes of `open` whose segment hits the triangle with corners
    /// `tri` (`Bvh::corner_words`), lanes whose direction's largest axis
    /// is `KZ` (`bvh::Shear::axes`): `bvh::hit_t` per lane, operation for
    /// operation. Lanes outside `open` may be set.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn hit<const KZ: usize>(l: &Lanes, tri: &[f32; 9], open: i32) -> i32 {
        let s1 = _mm256_set1_ps;
        let (mul, sub, add, and, or) = (
            _mm256_mul_ps,
            _mm256_sub_ps,
            _mm256_add_ps,
            _mm256_and_ps,
            _mm256_or_ps,
        );
        let [kx, ky, kz] = Shear::axes(KZ);
        // Corner c in the lanes' frames: a = v - o on axes kx, ky, kz,
        // then x, y sheared.
        let corner = |c: usize| {
            let a = |ax: usize| sub(s1(tri[3 * c + ax]), l.o[ax]);
            let (x, y, z) = (a(kx), a(ky), a(kz));
            (sub(x, mul(l.s[0], z)), sub(y, mul(l.s[1], z)), z)
        };
        let (ax, ay, az) = corner(0);
        let (bx, by, bz) = corner(1);
        let (cx, cy, cz) = corner(2);
        let u = sub(mul(cx, by), mul(cy, bx));
        let v = sub(mul(ax, cy), mul(ay, cx));
        let w = sub(mul(bx, ay), mul(by, ax));
        let zero = _mm256_setzero_ps();
        let lt = |x| _mm256_cmp_ps::<_CMP_LT_OQ>(x, zero);
        let gt = |x| _mm256_cmp_ps::<_CMP_GT_OQ>(x, zero);
        let neg = or(or(lt(u), lt(v)), lt(w));
        let pos = or(or(gt(u), gt(v)), gt(w));
        let inside = !_mm256_movemask_ps(and(neg, pos)) & open;
        if inside == 0 {
            return 0;
        }
        // det != 0 and finite (|det| < inf, false for NaN).
        let det = add(add(u, v), w);
        let abs = _mm256_andnot_ps(s1(-0.0), det);
        let ok = and(
            _mm256_cmp_ps::<_CMP_NEQ_OQ>(det, zero),
            _mm256_cmp_ps::<_CMP_LT_OQ>(abs, s1(f32::INFINITY)),
        );
        let sz = l.s[2];
        let t = add(
            add(mul(u, mul(sz, az)), mul(v, mul(sz, bz))),
            mul(w, mul(sz, cz)),
        );
        let t = _mm256_div_ps(t, det);
        let ok = and(ok, _mm256_cmp_ps::<_CMP_GT_OQ>(t, l.t0));
        let ok = and(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(t, l.t1));
        _mm256_movemask_ps(ok) & inside
    }

    /// `Bvh::occluded_lanes` (the caller checked a non-empty tree and an
    /// active lane): the wide nodes from `from` down, each slot's box
    /// tested for the lanes still open, a leaf's triangles for the lanes
    /// that entered it.
    #[target_feature(enable = "avx2")]
    pub(super) fn occluded(
        bvh: &Bvh,
        from: u32,
        rays: &Rays,
        active: Mask,
        t0: f32,
        t1: f32,
    ) -> (Mask, Option<u32>) {
        let l = lanes(rays, t0, t1);
        let (wide, nodes, tris) = (&bvh.wide, &bvh.nodes, bvh.corner_words());
        let mut open = active as i32;
        let mut found = None;
        // Binary trees are at most 60 levels deep (bvh.rs), wide ones 30,
        // with at most 3 pending children a level.
        let mut stack = [0u32; 96];
        stack[0] = from;
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let wk = stack[sp];
            let w = &wide[wk as usize];
            let n = w.len as usize;
            // The slots' tests do not depend on each other: the processor
            // overlaps them.
            let mut entered = [0i32; 4];
            for (k, e) in entered.iter_mut().enumerate().take(n) {
                *e = enter(&l, w, k);
            }
            for (k, &e) in entered.iter().enumerate().take(n) {
                let e = e & open;
                if e == 0 {
                    continue;
                }
                if w.leaves & (1 << k) == 0 {
                    debug_assert!(sp < stack.len());
                    stack[sp] = w.child[k];
                    sp += 1;
                    continue;
                }
                let leaf = &nodes[w.child[k] as usize];
                let s = leaf.start as usize;
                for tri in &tris[s..s + leaf.count as usize] {
                    let mut blocked = 0;
                    for (kz, &group) in rays.by_axis.iter().enumerate() {
                        let g = group as i32 & e & open;
                        if g != 0 {
                            blocked |= match kz {
                                0 => hit::<0>(&l, tri, g),
                                1 => hit::<1>(&l, tri, g),
                                _ => hit::<2>(&l, tri, g),
                            } & g;
                        }
                    }
                    if blocked != 0 {
                        open &= !blocked;
                        found = Some(wk);
                        if open == 0 {
                            return (active, found);
                        }
                    }
                }
            }
        }
        (active & !(open as Mask), found)
    }
}

/// The lanes in AVX-512 registers, two copies of the eight rays: one
/// instruction tests two of a wide node's slots, or two triangles, for all
/// eight rays, each operation the scalar one (as `avx2`: minps and maxps
/// keep their operand order; the 512-bit forms select alike).
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{Bvh, Mask, Rays};
    use crate::trace::bvh::{Shear, EXIT_SLACK};
    use crate::trace::bvh_wide::Wide;
    use core::arch::x86_64::*;

    /// The environment variable that, set to 1, keeps the AVX2 path on a
    /// CPU with AVX-512 (for comparing the two; both give the same bits).
    pub(crate) const NO_AVX512: &str = "SOFTSHADOW_NO_AVX512";

    /// Whether the CPU has AVX-512 F and DQ (and the OS keeps its state),
    /// unless `NO_AVX512` is 1.
    pub(super) fn available() -> bool {
        static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        *ON.get_or_init(|| {
            is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512dq")
                && std::env::var_os(NO_AVX512).is_none_or(|v| v != "1")
        })
    }

    struct Lanes {
        o: [__m512; 3],
        inv: [__m512; 3],
        s: [__m512; 3],
        t0: __m512,
        t1: __m512,
    }

    /// Eight f32s in both halves.
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn twice(a: &[f32; 8]) -> __m512 {
        // SAFETY: 8 f32s, an unaligned 256-bit load.
        let h = unsafe { _mm256_loadu_ps(a.as_ptr()) };
        _mm512_insertf32x8::<1>(_mm512_castps256_ps512(h), h)
    }

    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn lanes(rays: &Rays, t0: f32, t1: f32) -> Lanes {
        Lanes {
            o: rays.o.each_ref().map(|a| twice(a)),
            inv: rays.inv.each_ref().map(|a| twice(a)),
            s: rays.s.each_ref().map(|a| twice(a)),
            t0: _mm512_set1_ps(t0),
            t1: _mm512_set1_ps(t1),
        }
    }

    /// The lanes entering slot `a`'s box (low byte) and slot `b`'s (high
    /// byte) of `w`: `Bvh::enters` per lane, as `avx2::enter`.
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn enter(l: &Lanes, w: &Wide, a: usize, b: usize) -> u16 {
        let slab = |x: usize| {
            // Slot a's value in the low eight lanes, b's in the high: one
            // permute of the slots' row (two broadcasts and an insert took
            // more time a ray on mesh_125k and crowd: docs/methods/exact.md).
            let idx =
                _mm512_inserti64x4::<1>(_mm512_set1_epi32(a as i32), _mm256_set1_epi32(b as i32));
            // SAFETY: each row is 4 f32s, an unaligned 128-bit load.
            let ld = |r: &[f32; 4]| unsafe { _mm512_castps128_ps512(_mm_loadu_ps(r.as_ptr())) };
            let lo = _mm512_permutexvar_ps(idx, ld(&w.lo[x]));
            let hi = _mm512_permutexvar_ps(idx, ld(&w.hi[x]));
            let p = _mm512_mul_ps(_mm512_sub_ps(lo, l.o[x]), l.inv[x]);
            let q = _mm512_mul_ps(_mm512_sub_ps(hi, l.o[x]), l.inv[x]);
            (_mm512_min_ps(p, q), _mm512_max_ps(p, q))
        };
        let (n0, f0) = slab(0);
        let (n1, f1) = slab(1);
        let (n2, f2) = slab(2);
        let tmin = _mm512_max_ps(_mm512_max_ps(_mm512_max_ps(n0, n1), n2), l.t0);
        let exit = _mm512_min_ps(_mm512_min_ps(f0, f1), f2);
        let tmax = _mm512_min_ps(_mm512_mul_ps(exit, _mm512_set1_ps(EXIT_SLACK)), l.t1);
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(tmin, tmax)
    }

    /// The lanes hitting triangle `ta` (low byte) and `tb` (high byte),
    /// for lanes whose direction's largest axis is `KZ`: `avx2::hit`'s operations on
    /// sixteen lanes. `open`: the lanes that count (both bytes).
    #[inline]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn hit<const KZ: usize>(l: &Lanes, ta: &[f32; 9], tb: &[f32; 9], open: u16) -> u16 {
        let s1 = _mm512_set1_ps;
        let (mul, sub, add) = (_mm512_mul_ps, _mm512_sub_ps, _mm512_add_ps);
        // ta's 9 floats in one register, tb's in another; field f is lane f
        // of the first (low half) and of the second (high half).
        // SAFETY: 9 f32s each, masked loads of exactly those.
        let (x, y) = unsafe {
            (
                _mm512_maskz_loadu_ps(0x01FF, ta.as_ptr()),
                _mm512_maskz_loadu_ps(0x01FF, tb.as_ptr()),
            )
        };
        let field = |f: usize| {
            let idx = _mm512_inserti64x4::<1>(
                _mm512_set1_epi32(f as i32),
                _mm256_set1_epi32(16 + f as i32),
            );
            _mm512_permutex2var_ps(x, idx, y)
        };
        let [kx, ky, kz] = Shear::axes(KZ);
        let corner = |c: usize| {
            let a = |ax: usize| sub(field(3 * c + ax), l.o[ax]);
            let (x, y, z) = (a(kx), a(ky), a(kz));
            (sub(x, mul(l.s[0], z)), sub(y, mul(l.s[1], z)), z)
        };
        let (ax, ay, az) = corner(0);
        let (bx, by, bz) = corner(1);
        let (cx, cy, cz) = corner(2);
        let u = sub(mul(cx, by), mul(cy, bx));
        let v = sub(mul(ax, cy), mul(ay, cx));
        let w = sub(mul(bx, ay), mul(by, ax));
        let zero = _mm512_setzero_ps();
        let lt = |x| _mm512_cmp_ps_mask::<_CMP_LT_OQ>(x, zero);
        let gt = |x| _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, zero);
        let neg = lt(u) | lt(v) | lt(w);
        let pos = gt(u) | gt(v) | gt(w);
        let inside = !(neg & pos) & open;
        if inside == 0 {
            return 0;
        }
        let det = add(add(u, v), w);
        let ok = _mm512_cmp_ps_mask::<_CMP_NEQ_OQ>(det, zero)
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(det), s1(f32::INFINITY));
        let sz = l.s[2];
        let t = add(
            add(mul(u, mul(sz, az)), mul(v, mul(sz, bz))),
            mul(w, mul(sz, cz)),
        );
        let t = _mm512_div_ps(t, det);
        ok & inside
            & _mm512_cmp_ps_mask::<_CMP_GT_OQ>(t, l.t0)
            & _mm512_cmp_ps_mask::<_CMP_LT_OQ>(t, l.t1)
    }

    /// `avx2::occluded` with two slots, and two triangles, a test.
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn occluded(
        bvh: &Bvh,
        from: u32,
        rays: &Rays,
        active: Mask,
        t0: f32,
        t1: f32,
    ) -> (Mask, Option<u32>) {
        let l = lanes(rays, t0, t1);
        let (wide, nodes, tris) = (&bvh.wide, &bvh.nodes, bvh.corner_words());
        let mut open = active as i32;
        let mut found = None;
        let mut stack = [0u32; 96];
        stack[0] = from;
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let wk = stack[sp];
            let w = &wide[wk as usize];
            let n = w.len as usize;
            // Slots 0 and 1, then 2 and 3, with constant permutes (a
            // missing slot's box is zeros, tested and ignored: only the
            // first `n` are read).
            let e01 = enter(&l, w, 0, 1);
            let e23 = if n > 2 { enter(&l, w, 2, 3) } else { 0 };
            let entered = [
                (e01 & 0xFF) as i32,
                (e01 >> 8) as i32,
                (e23 & 0xFF) as i32,
                (e23 >> 8) as i32,
            ];
            for (k, &e) in entered.iter().enumerate().take(n) {
                let e = e & open;
                if e == 0 {
                    continue;
                }
                if w.leaves & (1 << k) == 0 {
                    debug_assert!(sp < stack.len());
                    stack[sp] = w.child[k];
                    sp += 1;
                    continue;
                }
                let leaf = &nodes[w.child[k] as usize];
                let s = leaf.start as usize;
                for two in tris[s..s + leaf.count as usize].chunks(2) {
                    let (ta, tb) = (&two[0], two.get(1).unwrap_or(&two[0]));
                    let mut blocked = 0;
                    for (kz, &group) in rays.by_axis.iter().enumerate() {
                        let g = (group as i32 & e & open) as u16;
                        if g != 0 {
                            let g2 = g | g << 8;
                            let h = match kz {
                                0 => hit::<0>(&l, ta, tb, g2),
                                1 => hit::<1>(&l, ta, tb, g2),
                                _ => hit::<2>(&l, ta, tb, g2),
                            };
                            blocked |= ((h & 0xFF) | (h >> 8)) as i32 & g as i32;
                        }
                    }
                    if blocked != 0 {
                        open &= !blocked;
                        found = Some(wk);
                        if open == 0 {
                            return (active, found);
                        }
                    }
                }
            }
        }
        (active & !(open as Mask), found)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::bvh::tests::rng;

    #[test]
    fn every_lane_answers_as_its_ray_alone() {
        // Random small triangles and rays from a few origins near each
        // other toward a light at z = 0, some through box edges.
        let mut r = rng(7);
        let tris: Vec<[Vec3; 3]> = (0..2000)
            .map(|_| {
                let c = Vec3::new(r() * 3.0 - 1.5, r() * 3.0 - 1.5, 1.0 + 2.0 * r());
                [
                    c,
                    c + Vec3::new(r() * 0.1, r() * 0.03, r() * 0.03),
                    c + Vec3::new(r() * 0.03, r() * 0.1, r() * 0.03),
                ]
            })
            .collect();
        let bvh = Bvh::build(tris);
        let mut blocked = 0;
        for _ in 0..3000 {
            let base = Vec3::new(r() * 3.0 - 1.5, r() * 3.0 - 1.5, 4.0);
            // Every other packet mixes the lanes' largest axes (some rays
            // come in from far off on x or y): each group of lanes is
            // tested in its own frame.
            let mixed = r() < 0.5;
            let o: [Vec3; LANES] = std::array::from_fn(|_| {
                let side = if !mixed {
                    Vec3::ZERO
                } else {
                    let sign = if r() < 0.5 { -8.0 } else { 8.0 };
                    [Vec3::ZERO, Vec3::X * sign, Vec3::Y * sign][(r() * 3.0) as usize % 3]
                };
                base + side + Vec3::new(r() * 0.05, r() * 0.05, 0.0)
            });
            let l = Vec3::new(r() - 0.5, r() - 0.5, 0.0);
            let d: [Vec3; LANES] =
                std::array::from_fn(|i| l + Vec3::new(r() * 0.06, r() * 0.06, 0.0) - o[i]);
            let active = (r() * 256.0) as Mask | 1;
            let rays = Rays::new(o, d);
            let (got, _) = bvh.occluded_lanes(0, &rays, active, 1e-5, 1.0 - 1e-5);
            let (scalar, _) = bvh.occluded_lanes_scalar(&rays, active, 1e-5, 1.0 - 1e-5);
            assert_eq!(got, scalar);
            for i in 0..LANES {
                let want = active & (1 << i) != 0 && bvh.occluded(o[i], d[i], 1e-5, 1.0 - 1e-5);
                assert_eq!(got & (1 << i) != 0, want, "lane {i}");
                blocked += want as u32;
            }
        }
        assert!(
            blocked > 1000,
            "the rays should often be blocked: {blocked}"
        );
    }

    /// Every SIMD path the CPU has (AVX2, and AVX-512 where it is there:
    /// `occluded_lanes` takes the widest) gives each lane the scalar
    /// answer, so results keep their bits whichever path a machine runs.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn every_simd_path_answers_as_the_scalar_one() {
        let mut r = rng(17);
        let tris: Vec<[Vec3; 3]> = (0..3000)
            .map(|_| {
                let c = Vec3::new(r() * 3.0 - 1.5, r() * 3.0 - 1.5, 1.0 + 2.0 * r());
                [
                    c,
                    c + Vec3::new(r() * 0.1, r() * 0.03, r() * 0.03),
                    c + Vec3::new(r() * 0.03, r() * 0.1, r() * 0.03),
                ]
            })
            .collect();
        let bvh = Bvh::build(tris);
        let avx2 = is_x86_feature_detected!("avx2");
        let avx512 = is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq");
        let mut checked = [0u32; 2];
        for _ in 0..3000 {
            let base = Vec3::new(r() * 3.0 - 1.5, r() * 3.0 - 1.5, 4.0);
            // Every other packet mixes the lanes' largest axes (some rays
            // come in from far off on x or y): each group of lanes is
            // tested in its own frame.
            let mixed = r() < 0.5;
            let o: [Vec3; LANES] = std::array::from_fn(|_| {
                let side = if !mixed {
                    Vec3::ZERO
                } else {
                    let sign = if r() < 0.5 { -8.0 } else { 8.0 };
                    [Vec3::ZERO, Vec3::X * sign, Vec3::Y * sign][(r() * 3.0) as usize % 3]
                };
                base + side + Vec3::new(r() * 0.05, r() * 0.05, 0.0)
            });
            let l = Vec3::new(r() - 0.5, r() - 0.5, 0.0);
            let d: [Vec3; LANES] =
                std::array::from_fn(|i| l + Vec3::new(r() * 0.06, r() * 0.06, 0.0) - o[i]);
            let active = (r() * 256.0) as Mask | 1;
            let rays = Rays::new(o, d);
            let (want, _) = bvh.occluded_lanes_scalar(&rays, active, 1e-5, 1.0 - 1e-5);
            if avx2 {
                // SAFETY: the CPU has AVX2.
                let (got, _) = unsafe { avx2::occluded(&bvh, 0, &rays, active, 1e-5, 1.0 - 1e-5) };
                assert_eq!(got, want, "avx2");
                checked[0] += 1;
            }
            if avx512 {
                // SAFETY: the CPU has AVX-512 F and DQ.
                let (got, _) =
                    unsafe { avx512::occluded(&bvh, 0, &rays, active, 1e-5, 1.0 - 1e-5) };
                assert_eq!(got, want, "avx512");
                checked[1] += 1;
            }
        }
        eprintln!("paths checked (avx2, avx512): {checked:?}");
    }

    #[test]
    fn no_lane_slips_between_triangles_that_share_an_edge() {
        // `bvh.rs`'s watertight test on every path: three copies of a
        // jittered grid, facing x, y and z, and packets whose lanes each
        // aim at one of them, through a shared edge or corner, steeper
        // than the grid's facets (so the line crosses the surface: a
        // grazing line may pass over a ridge). The lanes' largest axes
        // differ within a packet; every lane is blocked.
        let n = 16;
        let (grid, v, inner) = crate::trace::bvh::tests::jittered_grid(n, 21);
        let turn = |v: Vec3, k: usize| match k {
            0 => v,
            1 => Vec3::new(v.z, v.x, v.y),
            _ => Vec3::new(v.y, v.z, v.x),
        };
        let tris: Vec<[Vec3; 3]> = (0..3)
            .flat_map(|k| grid.iter().map(move |t| t.map(|v| turn(v, k))))
            .collect();
        let bvh = Bvh::build(tris);
        let rim = |q: usize| {
            let (i, j) = (q % n, q / n);
            i == 0 || j == 0 || i == n - 1 || j == n - 1
        };
        let mut r = rng(22);
        for p in 0..3000 {
            let mut o = [Vec3::ZERO; LANES];
            let mut d = [Vec3::ZERO; LANES];
            for i in 0..LANES {
                let [a, b] = inner[(p * LANES + i * 7) % inner.len()];
                // A third of the lanes through a corner (an inner one).
                let s = if i % 3 == 0 && !rim(a) { 0.0 } else { r() };
                let q = v[a] + (v[b] - v[a]) * s;
                let up = if r() < 0.5 { -1.0 } else { 1.0 } * (1.5 + 5.0 * r());
                let off = Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, up);
                let k = (r() * 3.0) as usize % 3;
                o[i] = turn(q + off, k);
                d[i] = (turn(q, k) - o[i]) * 2.0;
            }
            let rays = Rays::new(o, d);
            assert_eq!(bvh.occluded_lanes_scalar(&rays, ALL, 0.0, 1.0).0, ALL);
            assert_eq!(bvh.occluded_lanes(0, &rays, ALL, 0.0, 1.0).0, ALL);
            #[cfg(target_arch = "x86_64")]
            if is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2.
                let (got, _) = unsafe { avx2::occluded(&bvh, 0, &rays, ALL, 0.0, 1.0) };
                assert_eq!(got, ALL);
            }
        }
    }

    #[test]
    fn a_subtree_blocks_only_lanes_the_whole_tree_blocks() {
        // The shadow cache searches a subtree first: what it finds there
        // must be blocked in the whole tree too, and it must name a node
        // in that subtree.
        let mut r = rng(9);
        let tris: Vec<[Vec3; 3]> = (0..3000)
            .map(|_| {
                let c = Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, 1.0 + r());
                [
                    c,
                    c + Vec3::new(0.08, 0.0, 0.01),
                    c + Vec3::new(0.0, 0.08, 0.01),
                ]
            })
            .collect();
        let bvh = Bvh::build(tris);
        let mut from_cache = 0;
        for _ in 0..2000 {
            let base = Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, 4.0);
            let o: [Vec3; LANES] =
                std::array::from_fn(|_| base + Vec3::new(r() * 0.05, r() * 0.05, 0.0));
            let l = Vec3::new(r() - 0.5, r() - 0.5, 0.0);
            let d: [Vec3; LANES] = std::array::from_fn(|i| l - o[i]);
            let rays = Rays::new(o, d);
            let (all, node) = bvh.occluded_lanes(0, &rays, ALL, 1e-5, 1.0 - 1e-5);
            let Some(w) = node else { continue };
            let sub = bvh.wide_ancestor(w, 1);
            let (part, _) = bvh.occluded_lanes(sub, &rays, ALL, 1e-5, 1.0 - 1e-5);
            assert_eq!(part & !all, 0);
            from_cache += (part != 0) as u32;
        }
        assert!(
            from_cache > 100,
            "the subtree should often block: {from_cache}"
        );
    }

    #[test]
    fn axis_parallel_rays_through_box_faces_answer_as_alone() {
        // d.x = 0 exactly with o.x on a box face: 0 * inf = NaN in the slab
        // test, which the lanes must treat as the scalar test does.
        let tri = [
            Vec3::new(0.0, -1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        ];
        let bvh = Bvh::build(vec![tri]);
        let o: [Vec3; LANES] = std::array::from_fn(|i| match i {
            0 => Vec3::new(0.0, 0.0, 4.0),
            1 => Vec3::new(1.0, 0.0, 4.0),
            2 => Vec3::new(0.5, 1.0, 4.0),
            3 => Vec3::new(0.5, -1.0, 4.0),
            _ => Vec3::new(0.25 * i as f32 - 1.0, 0.1, 4.0),
        });
        let d: [Vec3; LANES] = std::array::from_fn(|i| Vec3::new(o[i].x, o[i].y, 0.0) - o[i]);
        let (got, _) = bvh.occluded_lanes(0, &Rays::new(o, d), ALL, 1e-5, 1.0 - 1e-5);
        for i in 0..LANES {
            let want = bvh.occluded(o[i], d[i], 1e-5, 1.0 - 1e-5);
            assert_eq!(got & (1 << i) != 0, want, "lane {i}");
        }
    }
}
