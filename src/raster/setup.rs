//! Triangle setup: projection of light-space triangles into the map, clipping
//! against the near plane and the guard band (`clip.rs`), and snapping of the
//! vertices to the fixed-point grid, giving the `SetupTri`s that both the CPU
//! scan (`scan.rs`) and the GPU rasterizer consume.

use crate::geom::clip::{clip_polygon, plane_dist, Plane};
use crate::geom::light::MapGrid;
use crate::raster::depth_plane::DepthPlane;
use glam::DVec3;
use rayon::prelude::*;

/// Sub-texel precision of snapped vertex coordinates.
pub(crate) const SUBPIXEL_BITS: u32 = 8;
pub(crate) const ONE: i64 = 1 << SUBPIXEL_BITS;
/// The guard band in texels on each side of the map. Coordinates stay below
/// (W + 2G) * 256 < 2^26 for W <= 2^16, so edge products fit in i64 exactly.
const GUARD: f64 = 4096.0;

/// A triangle ready to rasterize: snapped pixel coordinates, its 1/Z plane,
/// counter-clockwise in the sense that its edge functions are >= 0 inside.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SetupTri {
    pub x: [i64; 3],
    pub y: [i64; 3],
    /// 1/Z from the center of texel (i0, j0) on.
    pub depth: DepthPlane,
    /// Inclusive texel ranges covered by the bounding box, clamped to the map.
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
}

/// A vertex snapped to the fixed-point grid, with its 1/Z.
#[derive(Debug, Clone, Copy)]
struct Snapped {
    x: i64,
    y: i64,
    w: f64,
    inside: bool,
}

pub(super) struct Projector {
    grid: MapGrid,
    near: f64,
    planes: [Plane; 5],
    /// Largest |px| and |py| (texels) we accept without clipping.
    px_lo: f64,
    px_hi: f64,
    py_lo: f64,
    py_hi: f64,
}

impl Projector {
    pub(super) fn new(grid: &MapGrid, near: f64) -> Self {
        let gx = grid.tx * (1.0 + 2.0 * GUARD / grid.width as f64);
        let gy = grid.ty * (1.0 + 2.0 * GUARD / grid.height as f64);
        Projector {
            grid: *grid,
            near,
            planes: [
                [0.0, 0.0, 1.0, -near],
                [-1.0, 0.0, gx, 0.0], // X <= gx Z
                [1.0, 0.0, gx, 0.0],  // X >= -gx Z
                [0.0, -1.0, gy, 0.0], // Y <= gy Z
                [0.0, 1.0, gy, 0.0],  // Y >= -gy Z
            ],
            px_lo: -GUARD,
            px_hi: grid.width as f64 + GUARD,
            py_lo: -GUARD,
            py_hi: grid.height as f64 + GUARD,
        }
    }

    /// Continuous pixel coordinates and 1/Z of a light-space point with Z > 0.
    fn project(&self, q: DVec3) -> (f64, f64, f64) {
        let (px, py) = self.grid.to_pixel(q.x / q.z, q.y / q.z);
        (px, py, 1.0 / q.z)
    }

    /// Snaps a light-space point to the fixed-point grid; `inside` tells whether
    /// it lies in front of the near plane and within the guard band (so that
    /// a triangle of such vertices needs no clipping).
    fn snap(&self, q: DVec3) -> Snapped {
        let (px, py, w) = if q.z > 0.0 {
            self.project(q)
        } else {
            (f64::NAN, f64::NAN, 0.0)
        };
        let inside = q.z >= self.near
            && px >= self.px_lo
            && px <= self.px_hi
            && py >= self.py_lo
            && py <= self.py_hi;
        // Clipping may leave a vertex a hair outside the guard band: clamp.
        // (A vertex at or behind the light is never used unclipped.)
        let px = if px.is_nan() {
            0.0
        } else {
            px.clamp(self.px_lo, self.px_hi)
        };
        let py = if py.is_nan() {
            0.0
        } else {
            py.clamp(self.py_lo, self.py_hi)
        };
        Snapped {
            x: (px * ONE as f64).round() as i64,
            y: (py * ONE as f64).round() as i64,
            w,
            inside,
        }
    }

    /// Appends the rasterizable pieces of triangle (a, b, c) to `out`; `snapped`
    /// are the three vertices already snapped.
    fn setup(&self, tri: [DVec3; 3], snapped: [Snapped; 3], out: &mut Vec<SetupTri>) {
        if snapped.iter().all(|s| s.inside) {
            self.push_snapped(snapped, out);
            return;
        }
        // Trivially outside one plane: nothing to draw.
        if self
            .planes
            .iter()
            .any(|p| tri.iter().all(|&q| plane_dist(p, q) < 0.0))
        {
            return;
        }
        let mut poly: Vec<DVec3> = tri.to_vec();
        let mut tmp = Vec::with_capacity(9);
        for p in &self.planes {
            clip_polygon(p, &poly, &mut tmp);
            std::mem::swap(&mut poly, &mut tmp);
            if poly.len() < 3 {
                return;
            }
        }
        let s0 = self.snap(poly[0]);
        for k in 1..poly.len() - 1 {
            self.push_snapped([s0, self.snap(poly[k]), self.snap(poly[k + 1])], out);
        }
    }

    #[cfg(test)]
    pub(super) fn setup_unsnapped(&self, tri: [DVec3; 3], out: &mut Vec<SetupTri>) {
        self.setup(tri, tri.map(|q| self.snap(q)), out)
    }

    fn push_snapped(&self, v: [Snapped; 3], out: &mut Vec<SetupTri>) {
        let mut x = [v[0].x, v[1].x, v[2].x];
        let mut y = [v[0].y, v[1].y, v[2].y];
        let mut w = [v[0].w, v[1].w, v[2].w];
        let mut area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
        if area == 0 {
            return;
        }
        if area < 0 {
            x.swap(1, 2);
            y.swap(1, 2);
            w.swap(1, 2);
            area = -area;
        }
        // Texels whose center (i + 1/2) lies in [min, max].
        let span = |lo: i64, hi: i64, n: usize| -> Option<(u32, u32)> {
            // Arithmetic shifts: floor division by ONE, a power of two.
            let first = ((lo - ONE / 2 + ONE - 1) >> SUBPIXEL_BITS).max(0);
            let last = ((hi - ONE / 2) >> SUBPIXEL_BITS).min(n as i64 - 1);
            (first <= last).then_some((first as u32, last as u32))
        };
        let Some((i0, i1)) = span(
            *x.iter().min().unwrap(),
            *x.iter().max().unwrap(),
            self.grid.width,
        ) else {
            return;
        };
        let Some((j0, j1)) = span(
            *y.iter().min().unwrap(),
            *y.iter().max().unwrap(),
            self.grid.height,
        ) else {
            return;
        };
        // 1/Z at the center of texel (i0, j0) from the exact edge functions
        // there (barycentric, well conditioned), and its gradient per texel.
        let (cx, cy) = (i0 as i64 * ONE + ONE / 2, j0 as i64 * ONE + ONE / 2);
        // A triangle whose box holds one texel center and misses it writes
        // nothing: left out before its depth plane (most of a fine mesh's
        // triangles on a coarse map).
        if i0 == i1 && j0 == j1 && !super::edge::covers(&x, &y, cx, cy) {
            return;
        }
        let mut w_ref = 0f64;
        for (k, wk) in w.iter().enumerate() {
            let (s, e) = ((k + 1) % 3, (k + 2) % 3);
            let edge = (x[e] - x[s]) * (cy - y[s]) - (y[e] - y[s]) * (cx - x[s]);
            w_ref += edge as f64 * wk;
        }
        let area_f = area as f64;
        let (dx1, dy1) = ((x[1] - x[0]) as f64, (y[1] - y[0]) as f64);
        let (dx2, dy2) = ((x[2] - x[0]) as f64, (y[2] - y[0]) as f64);
        let (dw1, dw2) = (w[1] - w[0], w[2] - w[0]);
        let grad_i = (dw1 * dy2 - dw2 * dy1) / area_f * ONE as f64;
        let grad_j = (dx1 * dw2 - dx2 * dw1) / area_f * ONE as f64;
        out.push(SetupTri {
            x,
            y,
            depth: DepthPlane::new(w_ref / area_f, grad_i, grad_j),
            i0,
            i1,
            j0,
            j1,
        });
    }
}

/// `setup_triangles`, with the face each set-up triangle came from (a face
/// clipped into several pieces gives each piece its index).
pub(crate) fn setup_triangles_with_faces(
    grid: &MapGrid,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    near: f64,
) -> (Vec<SetupTri>, Vec<u32>) {
    let proj = Projector::new(grid, near);
    let snapped: Vec<Snapped> = verts.par_iter().map(|&q| proj.snap(q)).collect();
    faces
        .par_chunks(4096)
        .enumerate()
        .flat_map_iter(|(c, chunk)| {
            let mut out = Vec::with_capacity(chunk.len());
            let mut ids = Vec::with_capacity(chunk.len());
            for (k, f) in chunk.iter().enumerate() {
                let tri = f.map(|i| verts[i as usize]);
                let sn = f.map(|i| snapped[i as usize]);
                proj.setup(tri, sn, &mut out);
                ids.resize(out.len(), (c * 4096 + k) as u32);
            }
            out.into_iter().zip(ids)
        })
        .unzip()
}

/// Projects, clips and snaps a mesh whose vertices are already in light space
/// (f64) into triangles ready to rasterize; the GPU backend uploads these.
pub(crate) fn setup_triangles(
    grid: &MapGrid,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    near: f64,
) -> Vec<SetupTri> {
    let proj = Projector::new(grid, near);
    // Each vertex is projected and snapped once, however many faces share it.
    let snapped: Vec<Snapped> = verts.par_iter().map(|&q| proj.snap(q)).collect();
    faces
        .par_chunks(4096)
        .flat_map_iter(|chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            for f in chunk {
                let tri = f.map(|i| verts[i as usize]);
                let sn = f.map(|i| snapped[i as usize]);
                proj.setup(tri, sn, &mut out);
            }
            out
        })
        .collect()
}
