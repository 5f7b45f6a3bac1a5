//! CPU rasterizer of triangle meshes into light-view depth maps.
//!
//! * Sampling at texel centers; the depth is planar (light-space Z), which is
//!   interpolated as 1/Z, the quantity that is linear in the map's plane, in
//!   the f32 form of `depth_plane.rs` that the GPU rasterizer shares.
//! * Watertight: vertices are snapped to a fixed-point grid (1/256 texel) and edge
//!   functions are evaluated exactly in i64, with a tie rule that gives a texel
//!   center lying exactly on a shared edge to exactly one of the two triangles.
//! * Clipping: triangles are clipped in light space against a near plane and a
//!   guard band around the map (so that fixed-point coordinates stay small).
//!   An edge's intersection with a plane is computed from its endpoints in a
//!   canonical order, so two triangles sharing that edge get the same point.
//! * Parallel without locks: the map is cut into bands of rows; triangles are
//!   binned by band, and each band is rasterized by one task.

pub(crate) mod depth_plane;

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

/// Depth maps produced by one traversal of a mesh.
#[derive(Debug, Clone)]
pub struct DepthLayers {
    /// Nearest depth per texel, `inf` where nothing is hit.
    pub nearest: Vec<f32>,
    /// Farthest depth per texel (when asked for), `inf` where nothing is hit.
    pub farthest: Option<Vec<f32>>,
}

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

/// A clip plane in light space: keep points where a.X + b.Y + c.Z + d >= 0.
type Plane = [f64; 4];

fn plane_dist(p: &Plane, q: DVec3) -> f64 {
    p[0] * q.x + p[1] * q.y + p[2] * q.z + p[3]
}

fn lex_less(a: DVec3, b: DVec3) -> bool {
    (a.x, a.y, a.z) < (b.x, b.y, b.z)
}

/// Intersection of segment ab with plane p, computed from the lexicographically
/// smaller endpoint so that both triangles sharing the edge agree bit for bit.
fn clip_point(p: &Plane, a: DVec3, b: DVec3) -> DVec3 {
    let (s, e) = if lex_less(a, b) { (a, b) } else { (b, a) };
    let ds = plane_dist(p, s);
    let de = plane_dist(p, e);
    let t = ds / (ds - de);
    s + (e - s) * t
}

/// Sutherland-Hodgman against one plane. `out` is cleared first.
fn clip_polygon(p: &Plane, poly: &[DVec3], out: &mut Vec<DVec3>) {
    out.clear();
    let n = poly.len();
    for k in 0..n {
        let a = poly[k];
        let b = poly[(k + 1) % n];
        let da = plane_dist(p, a);
        let db = plane_dist(p, b);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(clip_point(p, a, b));
        }
    }
}

struct Projector {
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
    fn new(grid: &MapGrid, near: f64) -> Self {
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
    fn setup_unsnapped(&self, tri: [DVec3; 3], out: &mut Vec<SetupTri>) {
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

/// Rows per band: enough bands for load balance, few enough that binning is cheap.
fn band_rows(height: usize) -> usize {
    let bands = (rayon::current_num_threads() * 8).max(1);
    height.div_ceil(bands).max(1)
}

/// Tie rule for a texel center exactly on an edge (dx, dy): of an edge and its
/// reverse exactly one owns the center, so shared edges are neither cracked
/// nor hit twice.
#[inline]
fn owns_ties(dx: i64, dy: i64) -> bool {
    dy < 0 || (dy == 0 && dx > 0)
}

/// Visits the texel centers covered by triangle `t` within `rows`, calling
/// `write(index within the band, depth)` for each.
#[inline(always)]
fn raster_tri(
    t: &SetupTri,
    grid: &MapGrid,
    rows: std::ops::Range<usize>,
    mut write: impl FnMut(usize, f32),
) {
    let j_lo = (t.j0 as usize).max(rows.start);
    let j_hi = (t.j1 as usize + 1).min(rows.end);
    if j_lo >= j_hi {
        return;
    }
    let w = grid.width;
    // Edge k goes from vertex k+1 to vertex k+2; its function weighs vertex k.
    let mut a = [0i64; 3]; // dE/dx per texel
    let mut b = [0i64; 3]; // dE/dy per texel
    let mut c = [0i64; 3]; // E at texel center (i0, j_lo)
    let mut bias = [0i64; 3];
    let cx0 = t.i0 as i64 * ONE + ONE / 2;
    let cy0 = j_lo as i64 * ONE + ONE / 2;
    for k in 0..3 {
        let (s, e) = ((k + 1) % 3, (k + 2) % 3);
        let dx = t.x[e] - t.x[s];
        let dy = t.y[e] - t.y[s];
        a[k] = -dy * ONE;
        b[k] = dx * ONE;
        c[k] = dx * (cy0 - t.y[s]) - dy * (cx0 - t.x[s]);
        bias[k] = owns_ties(dx, dy) as i64;
    }
    for j in j_lo..j_hi {
        let dj = (j - j_lo) as i64;
        let mut e = [c[0] + b[0] * dj, c[1] + b[1] * dj, c[2] + b[2] * dj];
        let row = (j - rows.start) * w;
        for i in t.i0 as usize..=t.i1 as usize {
            if e[0] + bias[0] > 0 && e[1] + bias[1] > 0 && e[2] + bias[2] > 0 {
                if let Some(z) = t.depth.depth(i as u32 - t.i0, j as u32 - t.j0) {
                    write(row + i, z);
                }
            }
            e[0] += a[0];
            e[1] += a[1];
            e[2] += a[2];
        }
    }
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

/// A mesh set up for rasterization: triangles snapped and binned by band.
pub struct Prepared<'g> {
    grid: &'g MapGrid,
    tris: Vec<SetupTri>,
    /// Triangle indices of band b: binned[counts[b]..counts[b + 1]].
    binned: Vec<u32>,
    counts: Vec<u32>,
    rows_per_band: usize,
}

/// Relative depth gap under which a surface counts as the layer already peeled
/// (interpolated depths of one surface differ by a few f32 ulps).
pub(crate) const PEEL_GAP: f32 = 1e-5;

impl<'g> Prepared<'g> {
    /// Sets up a mesh whose vertices are already in light space. `near` is
    /// the clip distance from the light's plane: geometry closer than it (or
    /// behind the light) is cut away.
    pub fn new(grid: &'g MapGrid, verts: &[DVec3], faces: &[[u32; 3]], near: f64) -> Prepared<'g> {
        let tris = setup_triangles(grid, verts, faces, near);

        // Bin triangle indices by band (counting sort).
        let rows_per_band = band_rows(grid.height);
        let n_bands = grid.height.div_ceil(rows_per_band);
        let mut counts = vec![0u32; n_bands + 1];
        for t in &tris {
            for b in t.j0 as usize / rows_per_band..=t.j1 as usize / rows_per_band {
                counts[b + 1] += 1;
            }
        }
        for b in 0..n_bands {
            counts[b + 1] += counts[b];
        }
        let mut fill = counts.clone();
        let mut binned = vec![0u32; counts[n_bands] as usize];
        for (k, t) in tris.iter().enumerate() {
            for b in t.j0 as usize / rows_per_band..=t.j1 as usize / rows_per_band {
                binned[fill[b] as usize] = k as u32;
                fill[b] += 1;
            }
        }
        Prepared {
            grid,
            tris,
            binned,
            counts,
            rows_per_band,
        }
    }

    /// Runs `visit(band's rows, band's slice of each output, triangle)` for every
    /// band in parallel, each band owning its rows of the outputs.
    fn bands(
        &self,
        outputs: &mut [Vec<f32>],
        visit: impl Fn(&SetupTri, std::ops::Range<usize>, &mut [&mut [f32]]) + Sync,
    ) {
        let band_len = self.rows_per_band * self.grid.width;
        let mut per_band: Vec<Vec<&mut [f32]>> =
            (0..self.counts.len() - 1).map(|_| Vec::new()).collect();
        for out in outputs.iter_mut() {
            for (b, chunk) in out.chunks_mut(band_len).enumerate() {
                per_band[b].push(chunk);
            }
        }
        per_band
            .into_par_iter()
            .enumerate()
            .for_each(|(b, mut slices)| {
                let rows =
                    b * self.rows_per_band..((b + 1) * self.rows_per_band).min(self.grid.height);
                for &k in &self.binned[self.counts[b] as usize..self.counts[b + 1] as usize] {
                    visit(&self.tris[k as usize], rows.clone(), &mut slices);
                }
            });
    }

    /// The nearest depth per texel, and the farthest when asked for.
    pub fn nearest_farthest(&self, want_farthest: bool) -> DepthLayers {
        let mut outs = vec![vec![f32::INFINITY; self.grid.len()]];
        if want_farthest {
            outs.push(vec![f32::INFINITY; self.grid.len()]);
        }
        self.bands(&mut outs, |t, rows, o| {
            raster_tri(t, self.grid, rows, |idx, z| {
                if z < o[0][idx] {
                    o[0][idx] = z;
                }
                if let Some(f) = o.get_mut(1) {
                    if !(f[idx] < f32::INFINITY) || z > f[idx] {
                        f[idx] = z;
                    }
                }
            })
        });
        let farthest = want_farthest.then(|| outs.pop().unwrap());
        DepthLayers {
            nearest: outs.pop().unwrap(),
            farthest,
        }
    }

    /// Depth peeling: per texel, the nearest depth strictly beyond `previous`
    /// (by more than PEEL_GAP relative), `inf` where there is none.
    pub fn peel(&self, previous: &[f32]) -> Vec<f32> {
        let mut outs = vec![vec![f32::INFINITY; self.grid.len()]];
        let band_len = self.rows_per_band * self.grid.width;
        self.bands(&mut outs, |t, rows, o| {
            let base = rows.start / self.rows_per_band * band_len;
            raster_tri(t, self.grid, rows, |idx, z| {
                let floor = previous[base + idx];
                if z > floor * (1.0 + PEEL_GAP) && z < o[0][idx] {
                    o[0][idx] = z;
                }
            })
        });
        outs.pop().unwrap()
    }
}

/// Rasterizes a mesh whose vertices are already in light space into its
/// nearest (and farthest) depth maps.
pub fn rasterize(
    grid: &MapGrid,
    verts: &[DVec3],
    faces: &[[u32; 3]],
    near: f64,
    want_farthest: bool,
) -> DepthLayers {
    Prepared::new(grid, verts, faces, near).nearest_farthest(want_farthest)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> MapGrid {
        MapGrid::new(n, n, [1.0, 1.0]).unwrap()
    }

    /// A quad at depth z covering tangent [-s, s]^2, split along a diagonal.
    fn quad(z: f64, s: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let v = vec![
            DVec3::new(-s * z, -s * z, z),
            DVec3::new(s * z, -s * z, z),
            DVec3::new(s * z, s * z, z),
            DVec3::new(-s * z, s * z, z),
        ];
        (v, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn shared_edges_have_no_cracks_and_no_double_hits() {
        // A fan of many thin triangles around a center covering the whole map:
        // every texel center must be covered exactly once.
        let n = 64;
        let g = grid(n);
        let z = 2.0;
        let k = 37;
        let mut verts = vec![DVec3::new(0.013, -0.007, z)];
        for s in 0..k {
            let a = 2.0 * std::f64::consts::PI * s as f64 / k as f64;
            verts.push(DVec3::new(3.0 * a.cos() * z, 3.0 * a.sin() * z, z));
        }
        let faces: Vec<[u32; 3]> = (0..k)
            .map(|s| [0, 1 + s as u32, 1 + ((s + 1) % k) as u32])
            .collect();
        let proj = Projector::new(&g, 1e-9);
        let mut tris = Vec::new();
        for f in &faces {
            proj.setup_unsnapped(
                [
                    verts[f[0] as usize],
                    verts[f[1] as usize],
                    verts[f[2] as usize],
                ],
                &mut tris,
            );
        }
        let mut hits = vec![0u32; g.len()];
        for t in &tris {
            raster_tri(t, &g, 0..n, |idx, _| hits[idx] += 1);
        }
        assert!(hits.iter().all(|&h| h == 1), "hits: {:?}", &hits[..]);
    }

    #[test]
    fn exact_texel_center_edges_are_covered_once() {
        // Edges passing exactly through texel centers (diagonal of a quad whose
        // corners are texel centers).
        let n = 16;
        let g = grid(n);
        let z = 1.0;
        let c = |i: usize| g.x_of(i);
        let verts = [
            DVec3::new(c(2), c(2), z),
            DVec3::new(c(12), c(2), z),
            DVec3::new(c(12), c(12), z),
            DVec3::new(c(2), c(12), z),
        ];
        let faces = vec![[0, 1, 2], [0, 2, 3]];
        let proj = Projector::new(&g, 1e-9);
        let mut hits = vec![0u32; g.len()];
        for f in &faces {
            let mut tris = Vec::new();
            proj.setup_unsnapped(
                [
                    verts[f[0] as usize],
                    verts[f[1] as usize],
                    verts[f[2] as usize],
                ],
                &mut tris,
            );
            for t in &tris {
                raster_tri(t, &g, 0..n, |idx, _| hits[idx] += 1);
            }
        }
        assert!(hits.iter().all(|&h| h <= 1));
        // The diagonal's inner texel centers lie on the shared edge: each is
        // counted exactly once (the corners are on the quad's outer edges).
        for k in 3..=11 {
            assert_eq!(hits[(n - 1 - k) * n + k], 1, "diagonal texel {k}");
        }
    }

    #[test]
    fn planar_depth_is_exact_on_a_tilted_plane() {
        let g = grid(32);
        // Plane Z = 2 + 0.5 X (tilted), covering the whole view.
        let pts: Vec<DVec3> = [(-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)]
            .iter()
            .map(|&(x, y)| {
                // Point on the ray (x, y, 1) * t with t = 2 / (1 - 0.5 x).
                let t = 2.0 / (1.0 - 0.5 * x * 0.5);
                DVec3::new(x * 0.5 * t, y * 0.5 * t, t)
            })
            .collect();
        let faces = vec![[0, 1, 2], [0, 2, 3]];
        let d = rasterize(&g, &pts, &faces, 1e-9, true);
        for j in 0..32 {
            for i in 0..32 {
                let x = g.x_of(i);
                let expect = 2.0 / (1.0 - 0.5 * x);
                let got = d.nearest[j * 32 + i] as f64;
                assert!((got - expect).abs() < 1e-5 * expect, "{got} vs {expect}");
                assert_eq!(
                    d.nearest[j * 32 + i],
                    d.farthest.as_ref().unwrap()[j * 32 + i]
                );
            }
        }
    }

    #[test]
    fn nearest_and_farthest_layers_and_orientation() {
        let g = grid(8);
        let (mut v, mut f) = quad(2.0, 0.5);
        let (v2, f2) = quad(3.0, 0.25);
        let off = v.len() as u32;
        v.extend(v2);
        f.extend(f2.iter().map(|t| [t[0] + off, t[2] + off, t[1] + off]));
        let d = rasterize(&g, &v, &f, 1e-9, true);
        let far = d.farthest.unwrap();
        // Row 0 is +y; column 0 is -x. Texel centers at +-0.125 are inside both quads.
        let mid = 4 * 8 + 4;
        assert_eq!(d.nearest[mid], 2.0);
        assert_eq!(far[mid], 3.0);
        // Texel center x = 0.375 is inside only the first quad.
        let side = 4 * 8 + 5;
        assert_eq!(d.nearest[side], 2.0);
        assert_eq!(far[side], 2.0);
        assert!(d.nearest[0].is_infinite());
    }

    #[test]
    fn depth_peeling_finds_the_layers_in_order() {
        // Three stacked quads at depths 2, 3, 4 (the middle one smaller).
        let g = grid(8);
        let (mut v, mut f) = quad(2.0, 0.5);
        for (z, s) in [(3.0, 0.25), (4.0, 0.5)] {
            let (v2, f2) = quad(z, s);
            let off = v.len() as u32;
            v.extend(v2);
            f.extend(f2.iter().map(|t| t.map(|i| i + off)));
        }
        let p = Prepared::new(&g, &v, &f, 1e-9);
        let first = p.nearest_farthest(false).nearest;
        let second = p.peel(&first);
        let third = p.peel(&second);
        let fourth = p.peel(&third);
        let (mid, side) = (4 * 8 + 4, 4 * 8 + 5);
        assert_eq!([first[mid], second[mid], third[mid]], [2.0, 3.0, 4.0]);
        assert!(fourth[mid].is_infinite());
        // Outside the small quad the second layer is the far one.
        assert_eq!([first[side], second[side]], [2.0, 4.0]);
        assert!(third[side].is_infinite());
    }

    #[test]
    fn geometry_behind_the_light_is_clipped() {
        let g = grid(16);
        // A triangle crossing the light's plane: only the Z > 0 part is drawn,
        // with no inf or NaN depths.
        let v = vec![
            DVec3::new(-1.0, -1.0, -1.0),
            DVec3::new(1.0, -1.0, 3.0),
            DVec3::new(0.0, 2.0, 3.0),
        ];
        let d = rasterize(&g, &v, &[[0, 1, 2]], 1e-6, false);
        assert!(d
            .nearest
            .iter()
            .all(|z| z.is_infinite() || (*z > 0.0 && z.is_finite())));
        assert!(d.nearest.iter().any(|z| z.is_finite()));
    }
}
