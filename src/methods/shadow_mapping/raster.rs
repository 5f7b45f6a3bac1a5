//! The depth map of a standard shadow map (Williams 1978) under any
//! projection of `geom/shadow_projection.rs`, with the offsets of the bias
//! methods applied as the triangles are written (as glPolygonOffset does).
//!
//! Each triangle goes to clip space, is clipped against `w >= w_min` and
//! `|x|, |y| <= w` (Sutherland-Hodgman in homogeneous coordinates, in f64),
//! and is scanned at texel centres. Over a clipped triangle in map space the
//! hyperbolic depth z/w is affine, and so are 1/w and ℓ/w, whose ratio is
//! the linear depth ℓ (perspective-correct). As a hardware rasterizer (and
//! `crate::raster`) does, the map-space vertices are snapped to 1/256 texel
//! and the edge functions evaluated exactly in integers, so two triangles
//! sharing an edge compute exactly opposite values and a texel centre on it
//! goes to exactly one of them (a tie goes to the edge running up, or right
//! when horizontal). The depths are evaluated in f32 from planes split into
//! short limbs (`raster/depth_plane.rs`), the form the GPU twin
//! (`gpu/shadow_mapping.wgsl`) evaluates with the same bits.
//!
//! The offset written with a depth d is `slope · m + constant · 2⁻²⁴`,
//! m = max(|∂d/∂x|, |∂d/∂y|) per texel (glPolygonOffset's factor and units
//! on a 24-bit depth buffer over [0, 1]). Per texel the map keeps the
//! nearest depth and, when asked, the second nearest (two layers: Woo's
//! midpoint).

use crate::geom::shadow_projection::ShadowProjection;
use crate::raster::depth_plane::DepthPlane;
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
    /// The f32 form of `raster/depth_plane.rs` from the centre of texel
    /// (i0, j0) on.
    fn at_texel(&self, i0: u32, j0: u32) -> DepthPlane {
        DepthPlane::new(self.at(i0 as f64 + 0.5, j0 as f64 + 0.5), self.a, self.b)
    }
}

/// Sub-texel precision of the snapped map coordinates (as `crate::raster`).
pub const SUBPIXEL: i64 = 256;

/// A triangle in map space ready to scan, the same data for the CPU scan
/// below and the GPU's (`gpu/shadow_mapping.wgsl`): vertices snapped to
/// 1/SUBPIXEL texel (exact integer edge functions), counter-clockwise (edge
/// functions >= 0 inside), and its depths as f32 planes from the centre of
/// texel (i0, j0) on (`DepthPlane`: exact limb products, so a GPU that fuses
/// multiply-adds gets the same bits).
#[derive(Debug, Clone, Copy)]
pub struct SetupTri {
    pub x: [i32; 3],
    pub y: [i32; 3],
    /// Inclusive texel ranges of the bounding box, clamped to the map
    /// (empty when i0 > i1 or j0 > j1).
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
    /// z/w, 1/w and ℓ/w.
    pub zh: DepthPlane,
    pub iw: DepthPlane,
    pub lw: DepthPlane,
    /// The hyperbolic depth's whole offset (its slope is constant).
    pub zh_offset: f32,
    /// The linear depth's offset terms: `slope` times the per-texel slope
    /// plus `constant` (already in depth units).
    pub slope: f32,
    pub constant: f32,
    /// ∂(ℓ/w) and ∂(1/w) per texel along x and y.
    pub lw_a: f32,
    pub lw_b: f32,
    pub iw_a: f32,
    pub iw_b: f32,
}

/// `plane` at texel (i0 + di, j0 + dj): `DepthPlane::depth`'s sum, in its
/// order, without the reciprocal.
#[inline(always)]
fn plane_at(p: &DepthPlane, di: f32, dj: f32) -> f32 {
    let mut w = p.w_ref;
    for k in 0..3 {
        w += p.gx[k] * di;
        w += p.gy[k] * dj;
    }
    w
}

impl SetupTri {
    /// The depth (with its offset) written at texel (i, j) inside the
    /// triangle; `None` where it is not finite (or 1/w rounds to <= 0).
    /// The WGSL twin (`sm_depth`) does these f32 operations in this order.
    #[inline]
    pub fn depth(&self, i: usize, j: usize, distribution: Distribution) -> Option<f32> {
        let (di, dj) = ((i - self.i0 as usize) as f32, (j - self.j0 as usize) as f32);
        let z = match distribution {
            Distribution::Hyperbolic => plane_at(&self.zh, di, dj) + self.zh_offset,
            Distribution::Linear => {
                let a = plane_at(&self.lw, di, dj);
                let bw = plane_at(&self.iw, di, dj);
                if !(bw > 0.0) {
                    return None;
                }
                let d = a / bw;
                let dx = (self.lw_a - d * self.iw_a) / bw;
                let dy = (self.lw_b - d * self.iw_b) / bw;
                let m = dx.abs().max(dy.abs());
                d + (self.slope * m + self.constant)
            }
        };
        z.is_finite().then_some(z)
    }

    /// Whether texel centre (i, j) is inside (edge functions in i64, exact).
    #[inline]
    pub fn covers(&self, i: usize, j: usize) -> bool {
        let q = (
            i as i64 * SUBPIXEL + SUBPIXEL / 2,
            j as i64 * SUBPIXEL + SUBPIXEL / 2,
        );
        (0..3).all(|e| {
            let a = (self.x[e] as i64, self.y[e] as i64);
            let b = (self.x[(e + 1) % 3] as i64, self.y[(e + 1) % 3] as i64);
            let f = edge(a, b, q);
            f > 0 || (f == 0 && owns_tie(a, b))
        })
    }
}

/// The edge function of edge a→b at p (exact: integer coordinates).
#[inline]
fn edge(a: (i64, i64), b: (i64, i64), p: (i64, i64)) -> i64 {
    (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)
}

/// Whether a texel centre exactly on edge a→b belongs to this triangle
/// (of an edge and its reverse exactly one owns it).
#[inline]
fn owns_tie(a: (i64, i64), b: (i64, i64)) -> bool {
    b.1 > a.1 || (b.1 == a.1 && b.0 > a.0)
}

#[allow(clippy::too_many_arguments)]
fn setup(
    proj: &ShadowProjection,
    corners: [DVec3; 3],
    width: usize,
    height: usize,
    offset: Offset,
    out: &mut Vec<SetupTri>,
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
    // Clipped to |x|, |y| <= w: map coordinates in [0, W] x [0, H], a
    // little beyond by rounding; snapped they stay far inside i32.
    let lim = (MAX_SIDE as i64 + 2) * SUBPIXEL;
    let snap = |v: f64| ((v * SUBPIXEL as f64).round() as i64).clamp(-lim, lim);
    // Per vertex: map position, snapped position, (z/w, 1/w, ℓ/w).
    type MapVertex = ((f64, f64), (i64, i64), [f64; 3]);
    let map: Vec<MapVertex> = poly
        .iter()
        .map(|v| {
            let iw = 1.0 / v.c.w;
            let (x, y) = (v.c.x * iw, v.c.y * iw);
            let p = ((x + 1.0) * 0.5 * wf, (1.0 - y) * 0.5 * hf);
            (p, (snap(p.0), snap(p.1)), [v.c.z * iw, iw, v.l * iw])
        })
        .collect();
    for k in 1..map.len() - 1 {
        let mut t = [map[0], map[k], map[k + 1]];
        let area = edge(t[0].1, t[1].1, t[2].1);
        if area == 0 || !t.iter().all(|v| v.0 .0.is_finite() && v.0 .1.is_finite()) {
            continue;
        }
        if area < 0 {
            t.swap(1, 2);
        }
        let p = [t[0].0, t[1].0, t[2].0];
        let attr = |a: usize| [t[0].2[a], t[1].2[a], t[2].2[a]];
        let xs = t.map(|v| v.1 .0);
        let ys = t.map(|v| v.1 .1);
        // Texel centres i·S + S/2 inside [lo, hi].
        let first = |lo: i64| {
            (lo - SUBPIXEL / 2 + SUBPIXEL - 1)
                .div_euclid(SUBPIXEL)
                .max(0)
        };
        let last = |hi: i64, n: usize| (hi - SUBPIXEL / 2).div_euclid(SUBPIXEL).min(n as i64 - 1);
        let (i0, i1) = (
            first(*xs.iter().min().unwrap()),
            last(*xs.iter().max().unwrap(), width),
        );
        let (j0, j1) = (
            first(*ys.iter().min().unwrap()),
            last(*ys.iter().max().unwrap(), height),
        );
        if i1 < 0 || j1 < 0 {
            continue;
        }
        let (i0, j0) = (i0 as u32, j0 as u32);
        let (zh, iw, lw) = (
            Plane3::through(p, attr(0)),
            Plane3::through(p, attr(1)),
            Plane3::through(p, attr(2)),
        );
        let constant = offset.constant * DEPTH_STEP;
        out.push(SetupTri {
            x: xs.map(|v| v as i32),
            y: ys.map(|v| v as i32),
            i0,
            i1: i1 as u32,
            j0,
            j1: j1 as u32,
            zh: zh.at_texel(i0, j0),
            iw: iw.at_texel(i0, j0),
            lw: lw.at_texel(i0, j0),
            zh_offset: (offset.slope * zh.a.abs().max(zh.b.abs()) + constant) as f32,
            slope: offset.slope as f32,
            constant: constant as f32,
            lw_a: lw.a as f32,
            lw_b: lw.b as f32,
            iw_a: iw.a as f32,
            iw_b: iw.b as f32,
        });
    }
}

/// The largest side of a shadow map (16384² f32 is 1 GiB per layer), the
/// largest the set-up handles.
pub const MAX_SM_SIDE: usize = 16384;
const MAX_SIDE: usize = MAX_SM_SIDE;

/// The set-up triangles of the faces `which` of `faces` (world `verts`)
/// under `proj` on a (width, height) map, with `offset` baked in: the
/// per-call geometry both backends scan.
pub fn setup_triangles(
    proj: &ShadowProjection,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    (width, height): (usize, usize),
    offset: Offset,
    which: Faces,
) -> Vec<SetupTri> {
    faces
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
            setup(proj, c, width, height, offset, &mut out);
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        })
}

/// Rows per band of the parallel scan.
const BAND: usize = 16;

/// The depth map of set-up triangles `tris` (nearest, and the second
/// nearest when `two_layers`): the CPU scan, bands of rows in parallel.
pub fn scan(
    tris: &[SetupTri],
    (width, height): (usize, usize),
    distribution: Distribution,
    two_layers: bool,
) -> DepthMap {
    let bands = height.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![vec![]; bands];
    for (k, t) in tris.iter().enumerate() {
        if t.j0 > t.j1 || t.i0 > t.i1 {
            continue;
        }
        for bin in &mut bins[t.j0 as usize / BAND..=t.j1 as usize / BAND] {
            bin.push(k as u32);
        }
    }
    let mut nearest = vec![f32::INFINITY; width * height];
    let mut second = two_layers.then(|| vec![f32::INFINITY; width * height]);
    let scan = |b: usize, near: &mut [f32], mut sec: Option<&mut [f32]>| {
        let rows = b * BAND..((b + 1) * BAND).min(height);
        for &k in &bins[b] {
            let t = &tris[k as usize];
            for j in (t.j0 as usize).max(rows.start)..=(t.j1 as usize).min(rows.end - 1) {
                for i in t.i0 as usize..=t.i1 as usize {
                    if !t.covers(i, j) {
                        continue;
                    }
                    let Some(z) = t.depth(i, j, distribution) else {
                        continue;
                    };
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

/// The depth map of the faces `faces` of `verts` (world) under `proj`.
#[allow(clippy::too_many_arguments)]
pub fn rasterize(
    proj: &ShadowProjection,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    resolution: (usize, usize),
    distribution: Distribution,
    offset: Offset,
    which: Faces,
    two_layers: bool,
) -> DepthMap {
    let tris = setup_triangles(proj, verts, faces, resolution, offset, which);
    scan(&tris, resolution, distribution, two_layers)
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
