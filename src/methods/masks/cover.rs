//! Which light samples one triangle hides from one ray origin: the
//! triangle's shadow on the light, as half-planes in the light's (x, y).
//!
//! The segment from the origin o to the light point s = (x, y, 0) is
//! o + t d, d = s - o, and `exact` counts s hidden when it crosses the
//! triangle (v0, v1, v2), edges included, at t in (t0, t1)
//! (the watertight test, `bvh::hit_t`). With a_i = v_i - o and the triple
//! product T = a0 · (a1 x a2):
//!
//! * d passes through the triangle at some t > 0 iff it lies in the cone
//!   from o over the triangle: σ m_i · d >= 0 for the three edge normals
//!   m_01 = a0 x a1, m_12 = a1 x a2, m_20 = a2 x a0, σ = sign T;
//! * it crosses there at t* = T / (n · d), n = (v1 - v0) x (v2 - v0) (so
//!   n · a0 = T), with σ n · d > 0 inside the cone, and t* < t1 iff
//!   σ (t1 n · d - T) > 0, t* > t0 iff σ (T - t0 n · d) > 0.
//!
//! Each is linear in s, because d = s - o is: a + b x + c y. So the samples
//! a triangle hides from o are those inside at most five half-planes (four
//! where t0 = 0), the intersection of the plane z = 0 with the triangle's
//! shadow volume from o (Drettakis & Fiume 1994's backprojection, one
//! triangle at a time; Sintorn, Eisemann & Assarsson 2008 build the same
//! per-receiver sample masks from triangles on the GPU). A sixth keeps an
//! eye-view point's samples on one side of its tangent plane, where its
//! rays start above or below the surface (`eye::rays::RayStart`).
//!
//! The half-planes' coefficients are computed in f64 from the f32 corners
//! and evaluated in f32; the rays' test decides in f32 from other
//! products, so the two can differ on a sample within rounding of an edge
//! or of the triangle's plane: a ray that grazes (the masks' tests measure
//! how rarely, `tests.rs`). A degenerate triangle (T = 0: no area, or o in
//! its plane) hides nothing, as the rays' zero determinant does.

use super::cells::{Cells, LANE};
use glam::{DVec3, Vec3};

/// a + b x + c y >= 0 (> 0 where `strict`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HalfPlane {
    pub a: f32,
    pub b: f32,
    pub c: f32,
    pub strict: bool,
}

impl HalfPlane {
    /// Its value at (x, y), in the order `RayStart::origin` evaluates its
    /// side (the same bits for the same coefficients).
    #[inline(always)]
    pub fn at(&self, x: f32, y: f32) -> f32 {
        self.a + x * self.b + y * self.c
    }

    #[inline(always)]
    fn holds(&self, v: f32) -> bool {
        if self.strict {
            v > 0.0
        } else {
            v >= 0.0
        }
    }

    /// The complement (the points where this one fails), exactly: -v is
    /// the negated coefficients' value.
    pub fn not(&self) -> HalfPlane {
        HalfPlane {
            a: -self.a,
            b: -self.b,
            c: -self.c,
            strict: !self.strict,
        }
    }

    /// Whether it holds at no point, or at every point, of the box
    /// [lo, hi]: `Some(false)`, `Some(true)`, else None (the box straddles).
    #[inline(always)]
    pub fn on_box(&self, lo: [f32; 2], hi: [f32; 2]) -> Option<bool> {
        // The corners where b x + c y is smallest and largest (plain
        // selects: no NaN reaches a cell's box).
        let (xmin, xmax) = if self.b >= 0.0 {
            (lo[0], hi[0])
        } else {
            (hi[0], lo[0])
        };
        let (ymin, ymax) = if self.c >= 0.0 {
            (lo[1], hi[1])
        } else {
            (hi[1], lo[1])
        };
        let max = self.a + xmax * self.b + ymax * self.c;
        if !self.holds(max) {
            return Some(false);
        }
        let min = self.a + xmin * self.b + ymin * self.c;
        if self.holds(min) {
            Some(true)
        } else {
            None
        }
    }

    /// The columns [x0, x1] outside which it holds nowhere in the band of
    /// y in [y0, y1], widened by a hair over the rounding (it only skips
    /// cells where it holds at no sample); None where nowhere at all.
    /// `inv_b` is 1 / b (computed once a triangle, not once a row).
    #[inline(always)]
    fn x_span(&self, inv_b: f32, y0: f32, y1: f32) -> Option<[f32; 2]> {
        // The largest c y over the band.
        let k = self.a
            + if self.c >= 0.0 {
                y1 * self.c
            } else {
                y0 * self.c
            };
        if self.b == 0.0 {
            return (k >= 0.0).then_some([f32::NEG_INFINITY, f32::INFINITY]);
        }
        let x = -k * inv_b;
        // A hair over the rounding of x itself and of k (whose terms may
        // cancel): what is skipped lies outside the plane by more than
        // its own evaluation's rounding.
        let terms = self.a.abs() + (y0 * self.c).abs().max((y1 * self.c).abs());
        let pad = 1e-4 * (1.0 + x.abs()) + 1e-5 * terms * inv_b.abs();
        if !x.is_finite() {
            return Some([f32::NEG_INFINITY, f32::INFINITY]);
        }
        Some(if self.b > 0.0 {
            [x - pad, f32::INFINITY]
        } else {
            [f32::NEG_INFINITY, x + pad]
        })
    }
}

/// A triangle's shadow on the light seen from one origin: the half-planes
/// whose intersection it is (`n` of them).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cover {
    pub planes: [HalfPlane; PLANES],
    pub n: usize,
}

/// The most half-planes of a `Cover`: three edges, the segments' two
/// ends, the side of an eye-view point's tangent plane.
pub(crate) const PLANES: usize = 8;

impl Cover {
    pub fn new() -> Cover {
        let none = HalfPlane {
            a: 1.0,
            b: 0.0,
            c: 0.0,
            strict: false,
        };
        Cover {
            planes: [none; PLANES],
            n: 0,
        }
    }

    /// Adds a half-plane.
    pub fn and(mut self, p: HalfPlane) -> Cover {
        self.planes[self.n] = p;
        self.n += 1;
        self
    }

    /// Whether a plane holds at no point of the box [lo, hi] (`Ok(false)`:
    /// the triangle hides none of it), every plane everywhere (`Ok(true)`),
    /// else the planes that straddle it (a bit each). The first plane that
    /// misses the box ends the test (most cells a triangle's box reaches
    /// lie outside one of its edges).
    #[inline(always)]
    fn on_box(&self, lo: [f32; 2], hi: [f32; 2]) -> Result<bool, u8> {
        let mut straddle = 0u8;
        for (l, p) in self.planes[..self.n].iter().enumerate() {
            match p.on_box(lo, hi) {
                Some(false) => return Ok(false),
                Some(true) => {}
                None => straddle |= 1 << l,
            }
        }
        if straddle == 0 {
            Ok(true)
        } else {
            Err(straddle)
        }
    }
}

/// Where on the light `tri`'s shadow from `o` can fall: None where nowhere
/// (every corner at or behind the origin: the segments run from depth o.z
/// toward 0), `Some(None)` where no box bounds it (a corner behind the
/// origin), else a box holding the corners seen from o on the light's
/// plane (which bound the cone's section there), widened by a relative
/// hair: it only picks cells, and a sample on its edge must not be dropped
/// by its rounding.
#[inline(always)]
pub(crate) fn shadow_box(tri: &[Vec3; 3], o: Vec3) -> Option<Option<[[f32; 2]; 2]>> {
    let behind = [0, 1, 2].map(|i| tri[i].z >= o.z);
    if behind[0] && behind[1] && behind[2] {
        return None;
    }
    if behind[0] || behind[1] || behind[2] {
        return Some(None);
    }
    let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
    for v in tri {
        let k = o.z / (o.z - v.z);
        let p = [o.x + (v.x - o.x) * k, o.y + (v.y - o.y) * k];
        for j in 0..2 {
            lo[j] = lo[j].min(p[j]);
            hi[j] = hi[j].max(p[j]);
        }
    }
    let pad = 1e-4
        * (1.0
            + lo[0]
                .abs()
                .max(hi[0].abs())
                .max(lo[1].abs())
                .max(hi[1].abs()));
    let b = [[lo[0] - pad, hi[0] + pad], [lo[1] - pad, hi[1] + pad]];
    // A NaN (a corner within rounding of the origin's depth) bounds nothing.
    if b.iter().flatten().all(|x| x.is_finite()) {
        Some(Some(b))
    } else {
        Some(None)
    }
}

/// Whether the origin `o` and the whole light `rect` (z = 0) lie on one
/// side of `tri`'s plane, each farther from it than rounding reaches: then
/// no segment between them meets the plane, and the triangle hides
/// nothing (the rays' t lies outside (0, 1) by more than its
/// error). f64, from the f32 corners.
#[inline]
pub(crate) fn beside(tri: &[Vec3; 3], o: Vec3, rect: [[f32; 2]; 2]) -> bool {
    let t = tri.map(|v| v.as_dvec3());
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let at = |p: DVec3| n.dot(p - t[0]);
    let od = o.as_dvec3();
    let scale = t
        .iter()
        .chain(std::iter::once(&od))
        .fold(1.0f64, |m, p| m.max(p.abs().max_element()))
        .max(f64::from(
            rect[0][0]
                .abs()
                .max(rect[0][1].abs())
                .max(rect[1][0].abs())
                .max(rect[1][1].abs()),
        ));
    let margin = 1e-6 * n.length() * scale;
    let side = at(od);
    if !(side.abs() > margin) {
        return false;
    }
    let [[x0, x1], [y0, y1]] = rect.map(|r| r.map(f64::from));
    [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
        .iter()
        .all(|&(x, y)| at(DVec3::new(x, y, 0.0)) * side.signum() > margin)
}

/// `shadow_box` of the box [lo, hi]: its shadow from `o` on the light's
/// plane. A corner (x, z) lands at o.x + (x - o.x) o.z / (o.z - z), which
/// is monotone in x and in z, so the box's extremes are among its corners'.
#[inline(always)]
pub(crate) fn box_shadow(lo: Vec3, hi: Vec3, o: Vec3) -> Option<Option<[[f32; 2]; 2]>> {
    if lo.z >= o.z {
        return None;
    }
    if hi.z >= o.z {
        return Some(None);
    }
    let (k0, k1) = (o.z / (o.z - lo.z), o.z / (o.z - hi.z));
    let mut b = [[0f32; 2]; 2];
    for j in 0..2 {
        let (c0, c1) = (lo[j] - o[j], hi[j] - o[j]);
        let ps = [c0 * k0, c0 * k1, c1 * k0, c1 * k1];
        let min = ps[0].min(ps[1]).min(ps[2]).min(ps[3]);
        let max = ps[0].max(ps[1]).max(ps[2]).max(ps[3]);
        b[j] = [o[j] + min, o[j] + max];
    }
    let pad = 1e-4
        * (1.0
            + b[0][0]
                .abs()
                .max(b[0][1].abs())
                .max(b[1][0].abs())
                .max(b[1][1].abs()));
    let b = [
        [b[0][0] - pad, b[0][1] + pad],
        [b[1][0] - pad, b[1][1] + pad],
    ];
    if b.iter().flatten().all(|x| x.is_finite()) {
        Some(Some(b))
    } else {
        Some(None)
    }
}

/// The samples `tri` hides from `o` along segments t in (t0, t1), as half-
/// planes; None where it hides none (degenerate).
#[inline]
pub(crate) fn cover(tri: &[Vec3; 3], o: Vec3, t0: f32, t1: f32) -> Option<Cover> {
    let od = o.as_dvec3();
    let a = tri.map(|v| v.as_dvec3() - od);
    let m01 = a[0].cross(a[1]);
    let m12 = a[1].cross(a[2]);
    let m20 = a[2].cross(a[0]);
    let triple = m01.dot(a[2]);
    if triple == 0.0 || !triple.is_finite() {
        return None;
    }
    let sigma = triple.signum();
    // m · d = m.x x + m.y y - m · o for d = (x, y, 0) - o.
    let plane = |m: DVec3, k: f64, shift: f64, strict: bool| HalfPlane {
        a: (k * (-m.dot(od)) + shift) as f32,
        b: (k * m.x) as f32,
        c: (k * m.y) as f32,
        strict,
    };
    let n = m01 + m12 + m20;
    let mut c = Cover::new()
        .and(plane(m01, sigma, 0.0, false))
        .and(plane(m12, sigma, 0.0, false))
        .and(plane(m20, sigma, 0.0, false));
    // The hit lies where the segment reaches the triangle's depth z, at
    // t = 1 - z / o.z: with every corner deeper than (1 - t1) o.z and
    // shallower than (1 - t0) o.z by a margin over rounding, every hit
    // inside the cone has t in (t0, t1) and the ends' planes hold there.
    let (zmin, zmax) = (
        tri[0].z.min(tri[1].z).min(tri[2].z),
        tri[0].z.max(tri[1].z).max(tri[2].z),
    );
    let margin = 1.0 + 1e-3;
    if !(zmin > (1.0 - t1) * o.z * margin) {
        // σ (t1 n · d - T) > 0.
        c = c.and(plane(n, sigma * f64::from(t1), -sigma * triple, true));
    }
    if t0 > 0.0 && !(zmax * margin < (1.0 - t0) * o.z) {
        // σ (T - t0 n · d) > 0.
        c = c.and(plane(n, -sigma * f64::from(t0), sigma * triple, true));
    }
    Some(c)
}

/// The cells of `cells` the box `bbox` (None: the whole light) covers, as
/// ranges of columns and rows, or None where it misses the light.
#[inline(always)]
pub(crate) fn cell_range(
    cells: &Cells,
    bbox: Option<[[f32; 2]; 2]>,
) -> Option<([usize; 2], [usize; 2])> {
    let [[x0, x1], [y0, y1]] = match bbox {
        Some(b) => {
            let r = cells.rect;
            let b = [
                [b[0][0].max(r[0][0]), b[0][1].min(r[0][1])],
                [b[1][0].max(r[1][0]), b[1][1].min(r[1][1])],
            ];
            if !(b[0][0] <= b[0][1] && b[1][0] <= b[1][1]) {
                return None;
            }
            b
        }
        None => cells.rect,
    };
    let (ix0, iy0) = cells.cell_of(x0, y0);
    let (ix1, iy1) = cells.cell_of(x1, y1);
    Some(([ix0, ix1], [iy0, iy1]))
}

/// Whether every sample of the cells `range` is marked already.
#[inline(always)]
pub(crate) fn all_marked(cells: &Cells, mask: &[u64], range: ([usize; 2], [usize; 2])) -> bool {
    let ([ix0, ix1], [iy0, iy1]) = range;
    (iy0..=iy1).all(|iy| {
        let row = iy * cells.c;
        (row + ix0..=row + ix1).all(|k| mask[k] == cells.full[k])
    })
}

/// Marks in `mask` (a word a cell of `cells`) the samples inside every
/// half-plane of `cover` in the cells `range`; `open` counts the cells
/// with an unmarked sample and is kept.
#[inline(always)]
pub(crate) fn mark(
    cover: &Cover,
    cells: &Cells,
    range: ([usize; 2], [usize; 2]),
    mask: &mut [u64],
    open: &mut usize,
) {
    let ([ix0, ix1], [iy0, iy1]) = range;
    let planes = &cover.planes[..cover.n];
    let inv_b: [f32; PLANES] = std::array::from_fn(|l| 1.0 / cover.planes[l].b);
    for iy in iy0..=iy1 {
        // The columns of this row where every plane may hold: a thin or
        // slanted shadow crosses a few of the row's cells, not its box's.
        let [y0, y1] = cells.row_y[iy];
        let (mut xa, mut xb) = (f32::NEG_INFINITY, f32::INFINITY);
        for (p, &inv) in planes.iter().zip(&inv_b) {
            match p.x_span(inv, y0, y1) {
                Some([a, b]) => {
                    xa = xa.max(a);
                    xb = xb.min(b);
                }
                None => xb = f32::NEG_INFINITY,
            }
        }
        if !(xa <= xb) {
            continue;
        }
        let (ca, _) = cells.cell_of(xa.max(cells.rect[0][0]), y0);
        let (cb, _) = cells.cell_of(xb.min(cells.rect[0][1]), y0);
        for ix in ix0.max(ca)..=ix1.min(cb) {
            let k = iy * cells.c + ix;
            let full = cells.full[k];
            if mask[k] == full {
                continue;
            }
            let bits = match cover.on_box(cells.lo[k], cells.hi[k]) {
                Ok(false) => continue,
                Ok(true) => full,
                Err(straddle) => inside(cells, k, planes, u64::from(straddle)) & full,
            };
            let before = mask[k];
            mask[k] |= bits;
            if before != full && mask[k] == full {
                *open -= 1;
            }
        }
    }
}

/// The bits of cell k's samples inside every plane of `planes` whose bit
/// is set in `straddle` (bit 63: that plane and every later one; the
/// others hold on the whole cell), `LANE` samples at a time.
#[inline(always)]
pub(crate) fn inside(cells: &Cells, k: usize, planes: &[HalfPlane], straddle: u64) -> u64 {
    let s = cells.start[k] as usize;
    let n = cells.count[k] as usize;
    let mut bits = 0u64;
    for chunk in 0..n.div_ceil(LANE) {
        let at = s + chunk * LANE;
        let xs: &[f32; LANE] = cells.xs[at..at + LANE].try_into().unwrap();
        let ys: &[f32; LANE] = cells.ys[at..at + LANE].try_into().unwrap();
        let mut ok = [true; LANE];
        for (l, p) in planes.iter().enumerate() {
            if straddle >> l.min(63) & 1 == 0 {
                continue;
            }
            // Branch-free, so that the lanes run side by side.
            let loose = !p.strict;
            for j in 0..LANE {
                let v = p.at(xs[j], ys[j]);
                ok[j] &= (v > 0.0) | (loose & (v == 0.0));
            }
        }
        let mut b = 0u64;
        for (j, &o) in ok.iter().enumerate() {
            b |= u64::from(o) << j;
        }
        bits |= b << (chunk * LANE);
    }
    bits
}
