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
#[derive(Debug, Clone, Copy, PartialEq)]
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

/// `v.round()` (halves away from zero) without the libm call `f64::round`
/// compiles to on a baseline x86-64 target (a sixth of the snapping time on
/// 1 000 000 vertices); exact for |v| < 2^52, and every snapped coordinate
/// is far below that.
#[inline]
fn round_half_away(v: f64) -> i64 {
    let t = v as i64;
    let frac = v - t as f64;
    t + (frac >= 0.5) as i64 - (frac <= -0.5) as i64
}

/// A snapped vertex as the per-vertex arrays keep it (16 bytes, half of
/// `Snapped`): x is `OUTSIDE` where the vertex is not `inside`, and then no
/// face uses these fields unclipped.
#[derive(Debug, Clone, Copy)]
struct PackedVertex {
    x: i32,
    y: i32,
    w: f64,
}

/// `PackedVertex::x` of a vertex that needs clipping. Snapped coordinates
/// lie within (W + 2 GUARD) * ONE < 2^26 in magnitude, so it is never one.
const OUTSIDE: i32 = i32::MIN;

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
            x: round_half_away(px * ONE as f64),
            y: round_half_away(py * ONE as f64),
            w,
            inside,
        }
    }

    /// `snap` in the 16 bytes a vertex array holds (`PackedVertex`).
    fn snap_packed(&self, q: DVec3) -> PackedVertex {
        let s = self.snap(q);
        PackedVertex {
            x: if s.inside { s.x as i32 } else { OUTSIDE },
            y: s.y as i32,
            w: s.w,
        }
    }

    /// Appends the rasterizable pieces of the face whose snapped vertices
    /// are `packed` to `out`; `tri` gives its light-space corners, read only
    /// when the face needs clipping.
    #[inline]
    fn setup(
        &self,
        packed: [PackedVertex; 3],
        tri: impl FnOnce() -> [DVec3; 3],
        out: &mut Vec<SetupTri>,
    ) {
        if packed.iter().all(|p| p.x != OUTSIDE) {
            // Most faces of a fine mesh end in `push_snapped`'s first test
            // (their box holds no texel centre), before their corners are
            // read (2 000 000 faces at 640x480).
            self.push_snapped(
                packed.map(|p| Snapped {
                    x: p.x as i64,
                    y: p.y as i64,
                    w: p.w,
                    inside: true,
                }),
                out,
            );
            return;
        }
        self.clip_and_push(tri(), out);
    }

    /// The pieces of a face that crosses the near plane or the guard band.
    #[cold]
    fn clip_and_push(&self, tri: [DVec3; 3], out: &mut Vec<SetupTri>) {
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

    /// The texels whose centres (i + 1/2, j + 1/2) lie in the bounding box of
    /// snapped corners `x`, `y`, as inclusive ranges `((i0, i1), (j0, j1))`;
    /// `None` when there are none.
    #[inline]
    fn texel_box(&self, x: &[i64; 3], y: &[i64; 3]) -> Option<((u32, u32), (u32, u32))> {
        // The span of texel centres within snapped coordinates [lo, hi], as
        // (first, last), empty when first > last.
        let span = |lo: i64, hi: i64, n: usize| -> (i64, i64) {
            // Arithmetic shifts: floor division by ONE, a power of two.
            let first = ((lo - ONE / 2 + ONE - 1) >> SUBPIXEL_BITS).max(0);
            let last = ((hi - ONE / 2) >> SUBPIXEL_BITS).min(n as i64 - 1);
            (first, last)
        };
        let (x0, x1) = span(
            x[0].min(x[1]).min(x[2]),
            x[0].max(x[1]).max(x[2]),
            self.grid.width,
        );
        let (y0, y1) = span(
            y[0].min(y[1]).min(y[2]),
            y[0].max(y[1]).max(y[2]),
            self.grid.height,
        );
        (x0 <= x1 && y0 <= y1).then_some(((x0 as u32, x1 as u32), (y0 as u32, y1 as u32)))
    }

    #[cfg(test)]
    pub(super) fn setup_unsnapped(&self, tri: [DVec3; 3], out: &mut Vec<SetupTri>) {
        self.setup(tri.map(|q| self.snap_packed(q)), || tri, out)
    }

    fn push_snapped(&self, v: [Snapped; 3], out: &mut Vec<SetupTri>) {
        let mut x = [v[0].x, v[1].x, v[2].x];
        let mut y = [v[0].y, v[1].y, v[2].y];
        let mut w = [v[0].w, v[1].w, v[2].w];
        // The box first (the cheapest test, and the one most faces of a
        // fine mesh fail); it does not depend on the corners' order.
        let Some(((i0, i1), (j0, j1))) = self.texel_box(&x, &y) else {
            return;
        };
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

/// Faces set up per parallel task.
const CHUNK: usize = 4096;

/// `setup_triangles`, with the face each set-up triangle came from (a face
/// clipped into several pieces gives each piece its index).
pub(crate) fn setup_triangles_with_faces(
    grid: &MapGrid,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    near: f64,
) -> (Vec<SetupTri>, Vec<u32>) {
    let proj = Projector::new(grid, near);
    let snapped: Vec<PackedVertex> = verts.par_iter().map(|&q| proj.snap_packed(q)).collect();
    let chunks: Vec<(Vec<SetupTri>, Vec<u32>)> = faces
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let (mut out, mut ids) = (Vec::new(), Vec::new());
            for (k, f) in chunk.iter().enumerate() {
                let sn = f.map(|i| snapped[i as usize]);
                proj.setup(sn, || f.map(|i| verts[i as usize]), &mut out);
                ids.resize(out.len(), (c * CHUNK + k) as u32);
            }
            (out, ids)
        })
        .collect();
    let (tris, ids): (Vec<_>, Vec<_>) = chunks.into_iter().unzip();
    (concat(&tris), concat(&ids))
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
    let snapped: Vec<PackedVertex> = verts.par_iter().map(|&q| proj.snap_packed(q)).collect();
    let chunks: Vec<Vec<SetupTri>> = faces
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut out = Vec::new();
            for f in chunk {
                let sn = f.map(|i| snapped[i as usize]);
                proj.setup(sn, || f.map(|i| verts[i as usize]), &mut out);
            }
            out
        })
        .collect();
    concat(&chunks)
}

/// The chunks one after another, copied in parallel into one allocation
/// (rayon's collect of a flattened iterator copied 1 000 000 set-up
/// triangles at 1920x1080 twice, on one thread the second time).
fn concat<T: Copy + Send + Sync>(chunks: &[Vec<T>]) -> Vec<T> {
    let total = chunks.iter().map(Vec::len).sum();
    let mut out: Vec<T> = Vec::with_capacity(total);
    let mut rest = &mut out.spare_capacity_mut()[..total];
    let mut pieces = Vec::with_capacity(chunks.len());
    for c in chunks {
        let (piece, tail) = rest.split_at_mut(c.len());
        pieces.push(piece);
        rest = tail;
    }
    pieces
        .into_par_iter()
        .zip(chunks.par_iter())
        .for_each(|(piece, c)| {
            for (d, s) in piece.iter_mut().zip(c) {
                d.write(*s);
            }
        });
    // SAFETY: the pieces tile the first `total` slots of the spare capacity
    // and every slot of every piece was written just above.
    unsafe { out.set_len(total) };
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel setup gives the triangles (and faces) that setting up
    /// every face one by one gives, in order: fine faces mostly between
    /// texel centres, large ones, and faces crossing the near plane and
    /// the guard band.
    #[test]
    fn the_chunked_setup_is_the_setup_of_each_face() {
        let mut seed = 5u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let grid = MapGrid::new(64, 48, [1.0, 0.75]).unwrap();
        let mut verts = Vec::new();
        let mut faces = Vec::new();
        for k in 0..30_000u32 {
            let size = [0.002, 0.02, 0.5][k as usize % 3];
            let c = DVec3::new(4.0 * r() - 2.0, 3.0 * r() - 1.5, 2.0 * r() - 0.05);
            for _ in 0..3 {
                verts.push(c + size * DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5));
            }
            faces.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let near = 1e-3;
        let (tris, ids) = setup_triangles_with_faces(&grid, &verts, &faces, near);
        let proj = Projector::new(&grid, near);
        let (mut each, mut each_ids) = (Vec::new(), Vec::new());
        for (k, f) in faces.iter().enumerate() {
            proj.setup(
                f.map(|i| proj.snap_packed(verts[i as usize])),
                || f.map(|i| verts[i as usize]),
                &mut each,
            );
            each_ids.resize(each.len(), k as u32);
        }
        assert!(tris.len() > 2000 && tris.len() < 25_000, "{}", tris.len());
        assert_eq!(tris, each);
        assert_eq!(ids, each_ids);
        assert_eq!(setup_triangles(&grid, &verts, &faces, near), each);
    }

    /// The libm-free rounding is `f64::round` bit for bit: halves, values
    /// a hair either side of them, negatives and large coordinates.
    #[test]
    fn round_half_away_is_f64_round() {
        let mut seed = 7u64;
        let mut cases = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        for k in 0..200_000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            let v = (u - 0.5) * 2f64.powi(k % 40);
            let half = (v * 2.0).round() / 2.0;
            cases.extend([v, half, half.next_up(), half.next_down()]);
        }
        for v in cases {
            assert_eq!(round_half_away(v) as f64, v.round(), "{v}");
        }
    }

    #[test]
    fn concat_keeps_every_chunk_in_order() {
        let chunks: Vec<Vec<u32>> = (0..300u32)
            .map(|c| (0..(c * 7) % 13).map(|k| c * 100 + k).collect())
            .collect();
        let flat: Vec<u32> = chunks.iter().flatten().copied().collect();
        assert_eq!(concat(&chunks), flat);
        assert!(concat::<u32>(&[]).is_empty());
        assert!(concat::<u32>(&[vec![], vec![]]).is_empty());
    }
}
