//! The depth map of a standard shadow map (Williams 1978) under any
//! projection of `geom/shadow_projection.rs`, with the offsets of the bias
//! methods applied as the triangles are written (as glPolygonOffset does).
//!
//! Each triangle goes to clip space, is clipped against `w >= w_min` and
//! `|x|, |y| <= w` (Sutherland-Hodgman in homogeneous coordinates), and is
//! scanned at texel centres. Over a clipped triangle in map space the
//! hyperbolic depth z/w is affine, and so are 1/w and ℓ/w, whose ratio is
//! the linear depth ℓ (perspective-correct). Edge functions are evaluated
//! from each edge's lexicographically first end, so two triangles sharing
//! an edge compute exactly opposite values and a texel centre on it goes
//! to exactly one of them (a tie goes to the edge running up, or right
//! when horizontal).
//!
//! The offset written with a depth d is `slope · m + constant · 2⁻²⁴`,
//! m = max(|∂d/∂x|, |∂d/∂y|) per texel (glPolygonOffset's factor and units
//! on a 24-bit depth buffer over [0, 1]). Per texel the map keeps the
//! nearest depth and, when asked, the second nearest (two layers: Woo's
//! midpoint).

use crate::geom::shadow_projection::ShadowProjection;
use glam::{DVec3, DVec4};
use rayon::prelude::*;

/// Which depth the map holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Distribution {
    /// z/w, what a z-buffer holds.
    Hyperbolic,
    /// The distance along the light's axis, mapped onto [0, 1].
    Linear,
}

/// Which faces are written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Faces {
    All,
    /// Only faces turned away from the light (Wang & Molnar's second-depth
    /// idea for solid casters): `toward` gives the unit direction to the
    /// light from a point.
    BackOnly(Toward),
}

/// The direction toward the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Toward {
    /// A directional light: the same everywhere.
    Direction(DVec3),
    /// A point (a rectangle's centre).
    Point(DVec3),
}

impl Toward {
    pub fn at(&self, p: DVec3) -> DVec3 {
        match *self {
            Toward::Direction(d) => d,
            Toward::Point(c) => (c - p).normalize_or_zero(),
        }
    }
}

/// glPolygonOffset's two terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Offset {
    /// Times the smallest step of a 24-bit depth buffer, 2⁻²⁴.
    pub constant: f64,
    /// Times the depth's largest slope per texel.
    pub slope: f64,
}

/// One depth step of a 24-bit depth buffer over [0, 1].
pub const DEPTH_STEP: f64 = 1.0 / (1u64 << 24) as f64;

/// A shadow map's depths, row-major (H, W), `inf` where nothing is written.
#[derive(Debug, Clone)]
pub struct DepthMap {
    pub width: usize,
    pub height: usize,
    pub nearest: Vec<f32>,
    /// The second nearest, when two layers were asked for.
    pub second: Option<Vec<f32>>,
    /// Triangles written after clipping (for the study).
    pub triangles: usize,
}

impl DepthMap {
    /// Continuous texel coordinates of map point (u, v): texel [j, i] has
    /// its centre at (i, j).
    pub fn texel_of(&self, u: f64, v: f64) -> (f64, f64) {
        (
            (u + 1.0) * 0.5 * self.width as f64 - 0.5,
            (1.0 - v) * 0.5 * self.height as f64 - 0.5,
        )
    }
}

/// A clipped vertex: clip coordinates and the linear depth.
#[derive(Debug, Clone, Copy)]
struct Clip {
    c: DVec4,
    l: f64,
}

impl Clip {
    fn lerp(a: Clip, b: Clip, t: f64) -> Clip {
        Clip {
            c: a.c + (b.c - a.c) * t,
            l: a.l + (b.l - a.l) * t,
        }
    }
}

fn clip_against(poly: &[Clip], dist: impl Fn(DVec4) -> f64, out: &mut Vec<Clip>) {
    out.clear();
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (da, db) = (dist(a.c), dist(b.c));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            // From the lexicographically first end: both neighbours agree.
            let key = |c: DVec4| (c.x, c.y, c.z, c.w);
            let (s, e, ds, de) = if key(a.c) < key(b.c) {
                (a, b, da, db)
            } else {
                (b, a, db, da)
            };
            out.push(Clip::lerp(s, e, ds / (ds - de)));
        }
    }
}

/// An affine function of map position: a x + b y + c.
#[derive(Debug, Clone, Copy)]
struct Plane3 {
    a: f64,
    b: f64,
    c: f64,
}

impl Plane3 {
    fn through(p: [(f64, f64); 3], v: [f64; 3]) -> Plane3 {
        let (x1, y1) = (p[1].0 - p[0].0, p[1].1 - p[0].1);
        let (x2, y2) = (p[2].0 - p[0].0, p[2].1 - p[0].1);
        let det = x1 * y2 - x2 * y1;
        let (d1, d2) = (v[1] - v[0], v[2] - v[0]);
        let a = (d1 * y2 - d2 * y1) / det;
        let b = (x1 * d2 - x2 * d1) / det;
        Plane3 {
            a,
            b,
            c: v[0] - a * p[0].0 - b * p[0].1,
        }
    }
    #[inline]
    fn at(&self, x: f64, y: f64) -> f64 {
        self.a * x + self.b * y + self.c
    }
}

/// A triangle in map space ready to scan.
#[derive(Debug, Clone, Copy)]
struct Tri {
    p: [(f64, f64); 3],
    /// z/w, 1/w and ℓ/w.
    zh: Plane3,
    iw: Plane3,
    lw: Plane3,
    j0: usize,
    j1: usize,
    i0: usize,
    i1: usize,
}

/// The edge function of edge a→b at p, computed from the edge's
/// lexicographically first end (exactly opposite for b→a).
#[inline]
fn edge(a: (f64, f64), b: (f64, f64), p: (f64, f64)) -> f64 {
    if a < b {
        (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)
    } else {
        -((a.0 - b.0) * (p.1 - b.1) - (a.1 - b.1) * (p.0 - b.0))
    }
}

/// Whether a texel centre exactly on edge a→b belongs to this triangle.
#[inline]
fn owns_tie(a: (f64, f64), b: (f64, f64)) -> bool {
    b.1 > a.1 || (b.1 == a.1 && b.0 > a.0)
}

fn setup(
    proj: &ShadowProjection,
    corners: [DVec3; 3],
    width: usize,
    height: usize,
    out: &mut Vec<Tri>,
) {
    let h = |p: DVec3| {
        let q = p.extend(1.0);
        Clip {
            c: proj.m * q,
            l: proj.lin.dot(q),
        }
    };
    let mut poly: Vec<Clip> = corners.iter().map(|p| h(*p)).collect();
    let mut next = Vec::with_capacity(9);
    let w_min = proj.w_min;
    let planes: [&dyn Fn(DVec4) -> f64; 5] = [
        &|c: DVec4| c.w - w_min,
        &|c: DVec4| c.w - c.x,
        &|c: DVec4| c.w + c.x,
        &|c: DVec4| c.w - c.y,
        &|c: DVec4| c.w + c.y,
    ];
    for p in planes {
        clip_against(&poly, p, &mut next);
        std::mem::swap(&mut poly, &mut next);
        if poly.len() < 3 {
            return;
        }
    }
    let (wf, hf) = (width as f64, height as f64);
    let map: Vec<((f64, f64), [f64; 3])> = poly
        .iter()
        .map(|v| {
            let iw = 1.0 / v.c.w;
            let (x, y) = (v.c.x * iw, v.c.y * iw);
            (
                ((x + 1.0) * 0.5 * wf, (1.0 - y) * 0.5 * hf),
                [v.c.z * iw, iw, v.l * iw],
            )
        })
        .collect();
    for k in 1..map.len() - 1 {
        let mut t = [map[0], map[k], map[k + 1]];
        let area = edge(t[0].0, t[1].0, t[2].0);
        if !(area.abs() > 1e-12) || !area.is_finite() {
            continue;
        }
        if area < 0.0 {
            t.swap(1, 2);
        }
        let p = [t[0].0, t[1].0, t[2].0];
        let attr = |a: usize| [t[0].1[a], t[1].1[a], t[2].1[a]];
        let (xs, ys) = (p.map(|q| q.0), p.map(|q| q.1));
        let lo = |v: [f64; 3]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = |v: [f64; 3]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // Texel centres at i + 1/2 inside [lo, hi].
        let first = |l: f64| (l - 0.5).ceil().max(0.0) as usize;
        let last = |h: f64, n: usize| ((h - 0.5).floor().min(n as f64 - 1.0)).max(-1.0);
        let (i1, j1) = (last(hi(xs), width), last(hi(ys), height));
        if i1 < 0.0 || j1 < 0.0 {
            continue;
        }
        out.push(Tri {
            p,
            zh: Plane3::through(p, attr(0)),
            iw: Plane3::through(p, attr(1)),
            lw: Plane3::through(p, attr(2)),
            i0: first(lo(xs)),
            i1: i1 as usize,
            j0: first(lo(ys)),
            j1: j1 as usize,
        });
    }
}

/// Rows per band of the parallel scan.
const BAND: usize = 16;

/// The depth map of the faces `faces` of `verts` (world) under `proj`.
#[allow(clippy::too_many_arguments)]
pub fn rasterize(
    proj: &ShadowProjection,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    (width, height): (usize, usize),
    distribution: Distribution,
    offset: Offset,
    which: Faces,
    two_layers: bool,
) -> DepthMap {
    let tris: Vec<Tri> = faces
        .par_iter()
        .with_min_len(256)
        .fold(Vec::new, |mut out, f| {
            let c = f.map(|i| verts[i as usize]);
            if let Faces::BackOnly(toward) = which {
                let n = (c[1] - c[0]).cross(c[2] - c[0]);
                let centroid = (c[0] + c[1] + c[2]) / 3.0;
                if !(n.dot(toward.at(centroid)) < 0.0) {
                    return out;
                }
            }
            setup(proj, c, width, height, &mut out);
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    let bands = height.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![vec![]; bands];
    for (k, t) in tris.iter().enumerate() {
        if t.j0 > t.j1 || t.i0 > t.i1 {
            continue;
        }
        for bin in &mut bins[t.j0 / BAND..=t.j1 / BAND] {
            bin.push(k as u32);
        }
    }
    let mut nearest = vec![f32::INFINITY; width * height];
    let mut second = two_layers.then(|| vec![f32::INFINITY; width * height]);
    let scan = |b: usize, near: &mut [f32], mut sec: Option<&mut [f32]>| {
        let rows = b * BAND..((b + 1) * BAND).min(height);
        for &k in &bins[b] {
            let t = &tris[k as usize];
            for j in t.j0.max(rows.start)..=t.j1.min(rows.end - 1) {
                let y = j as f64 + 0.5;
                for i in t.i0..=t.i1 {
                    let x = i as f64 + 0.5;
                    let q = (x, y);
                    let mut inside = true;
                    for e in 0..3 {
                        let (a, bb) = (t.p[e], t.p[(e + 1) % 3]);
                        let f = edge(a, bb, q);
                        if f < 0.0 || (f == 0.0 && !owns_tie(a, bb)) {
                            inside = false;
                            break;
                        }
                    }
                    if !inside {
                        continue;
                    }
                    let (d, dx, dy) = match distribution {
                        Distribution::Hyperbolic => (t.zh.at(x, y), t.zh.a, t.zh.b),
                        Distribution::Linear => {
                            let (a, bw) = (t.lw.at(x, y), t.iw.at(x, y));
                            let d = a / bw;
                            (d, (t.lw.a - d * t.iw.a) / bw, (t.lw.b - d * t.iw.b) / bw)
                        }
                    };
                    let m = dx.abs().max(dy.abs());
                    let z = (d + offset.slope * m + offset.constant * DEPTH_STEP) as f32;
                    if !z.is_finite() {
                        continue;
                    }
                    let o = (j - rows.start) * width + i;
                    if z < near[o] {
                        if let Some(s) = sec.as_deref_mut() {
                            s[o] = near[o];
                        }
                        near[o] = z;
                    } else if let Some(s) = sec.as_deref_mut() {
                        if z < s[o] {
                            s[o] = z;
                        }
                    }
                }
            }
        }
    };
    match &mut second {
        Some(sec) => nearest
            .par_chunks_mut(BAND * width)
            .zip(sec.par_chunks_mut(BAND * width))
            .enumerate()
            .for_each(|(b, (n, s))| scan(b, n, Some(s))),
        None => nearest
            .par_chunks_mut(BAND * width)
            .enumerate()
            .for_each(|(b, n)| scan(b, n, None)),
    }
    DepthMap {
        width,
        height,
        nearest,
        second,
        triangles: tris.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun_map(points: &[DVec3]) -> ShadowProjection {
        ShadowProjection::orthographic(-DVec3::Y, DVec3::X, DVec3::Z, points).unwrap()
    }

    fn quad(y: f64, s: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        (
            vec![
                DVec3::new(-s, y, -s),
                DVec3::new(s, y, -s),
                DVec3::new(s, y, s),
                DVec3::new(-s, y, s),
            ],
            vec![[0, 2, 1], [0, 3, 2]],
        )
    }

    #[test]
    fn a_quad_covering_the_map_writes_every_texel_once() {
        let (v, f) = quad(0.0, 1.0);
        let bounds = [DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 1.0)];
        let p = sun_map(&bounds);
        let m = rasterize(
            &p,
            &v,
            &f,
            (33, 17),
            Distribution::Linear,
            Offset::default(),
            Faces::All,
            true,
        );
        // Depth along -y from y = 1: 0.5 of the range, everywhere; the
        // diagonal's texels are written by one triangle only.
        assert!(m.nearest.iter().all(|&z| (z - 0.5).abs() < 1e-6));
        assert!(m.second.unwrap().iter().all(|z| z.is_infinite()));
    }

    #[test]
    fn two_layers_keep_the_two_nearest_and_offsets_add() {
        let (mut v, mut f) = quad(0.5, 0.5);
        let (v2, f2) = quad(-0.5, 1.0);
        f.extend(f2.iter().map(|t| t.map(|i| i + 4)));
        v.extend(v2);
        let bounds = [DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 1.0)];
        let p = sun_map(&bounds);
        let m = rasterize(
            &p,
            &v,
            &f,
            (16, 16),
            Distribution::Linear,
            Offset::default(),
            Faces::All,
            true,
        );
        let s = m.second.as_ref().unwrap();
        // Centre texel: the small quad at depth 0.25, the floor at 0.75.
        let c = 8 * 16 + 8;
        assert!((m.nearest[c] - 0.25).abs() < 1e-6 && (s[c] - 0.75).abs() < 1e-6);
        // A corner texel sees only the floor.
        assert!((m.nearest[0] - 0.75).abs() < 1e-6 && s[0].is_infinite());
        let off = Offset {
            constant: 1000.0,
            slope: 0.0,
        };
        let m2 = rasterize(
            &p,
            &v,
            &f,
            (16, 16),
            Distribution::Linear,
            off,
            Faces::All,
            false,
        );
        assert!((m2.nearest[c] as f64 - 0.25 - 1000.0 * DEPTH_STEP).abs() < 1e-6);
    }

    #[test]
    fn slope_offsets_grow_with_the_tilt() {
        // A plane tilted in x: its depth changes by 1/16 of the range per
        // texel of a 16-wide map over [-1, 1] when the tilt is 45 degrees.
        let v = vec![
            DVec3::new(-1.0, -1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        let f = vec![[0u32, 2, 1], [0, 3, 2]];
        let p = sun_map(&v);
        let plain = rasterize(
            &p,
            &v,
            &f,
            (16, 16),
            Distribution::Hyperbolic,
            Offset::default(),
            Faces::All,
            false,
        );
        let off = Offset {
            constant: 0.0,
            slope: 2.0,
        };
        let sloped = rasterize(
            &p,
            &v,
            &f,
            (16, 16),
            Distribution::Hyperbolic,
            off,
            Faces::All,
            false,
        );
        for (a, b) in plain.nearest.iter().zip(&sloped.nearest) {
            assert!(((b - a) as f64 - 2.0 / 16.0).abs() < 1e-5, "{a} {b}");
        }
    }

    #[test]
    fn back_faces_only_writes_the_far_side() {
        // A unit cube: seen from above (light travelling -y), its top faces
        // the light and its bottom away.
        let v: Vec<DVec3> = (0..8)
            .map(|k| {
                DVec3::new(
                    (k & 1) as f64 - 0.5,
                    ((k >> 1) & 1) as f64 - 0.5,
                    ((k >> 2) & 1) as f64 - 0.5,
                )
            })
            .collect();
        // Top (y = 0.5: vertices 2, 3, 6, 7) normal +y, bottom normal -y.
        let f = vec![[2u32, 6, 7], [2, 7, 3], [0, 1, 5], [0, 5, 4]];
        let bounds = [DVec3::splat(-1.0), DVec3::splat(1.0)];
        let p = sun_map(&bounds);
        let toward = Toward::Direction(DVec3::Y);
        let all = rasterize(
            &p,
            &v,
            &f,
            (8, 8),
            Distribution::Linear,
            Offset::default(),
            Faces::All,
            false,
        );
        let back = rasterize(
            &p,
            &v,
            &f,
            (8, 8),
            Distribution::Linear,
            Offset::default(),
            Faces::BackOnly(toward),
            false,
        );
        let c = 4 * 8 + 4;
        assert!((all.nearest[c] - 0.25).abs() < 1e-6);
        assert!((back.nearest[c] - 0.75).abs() < 1e-6);
    }

    #[test]
    fn perspective_maps_clip_what_lies_behind_the_light() {
        // A triangle crossing the light's plane: only its front part is
        // written, and no depth is negative or NaN.
        let v = vec![
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(1.0, 0.5, 2.0),
            DVec3::new(-1.0, 1.0, 2.0),
        ];
        let f = vec![[0u32, 1, 2]];
        let pts = [DVec3::new(-1.0, -1.0, 1.0), DVec3::new(1.0, 1.0, 3.0)];
        let p =
            ShadowProjection::perspective(DVec3::ZERO, DVec3::Z, DVec3::X, DVec3::Y, &pts).unwrap();
        for d in [Distribution::Hyperbolic, Distribution::Linear] {
            let m = rasterize(
                &p,
                &v,
                &f,
                (32, 32),
                d,
                Offset::default(),
                Faces::All,
                false,
            );
            assert!(m
                .nearest
                .iter()
                .all(|z| z.is_infinite() || (*z >= -1e-6 && z.is_finite())));
            assert!(m.nearest.iter().any(|z| z.is_finite()));
        }
    }
}
