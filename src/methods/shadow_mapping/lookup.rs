//! The depth test of a shadow map at a point, with its bias method and
//! filter (Williams 1978; Reeves et al. 1987 for PCF).
//!
//! A point p projects to map position (x, y) (texel [j, i] centred at
//! (i, j)) and depth d_p in the map's distribution. Texel k passes (lit)
//! when `d_p <= D_k`, D_k the depth written there (offset by the bias
//! method), or for Woo's midpoint `d_p <= (D1_k + D2_k)/2` (an empty second
//! layer makes the midpoint infinite: a single surface never shadows
//! itself). Without a filter the nearest texel decides (0 or 1); with
//! `Pcf { size }` the result is the mean of size×size taps one texel apart
//! centred on (x, y), each the bilinear blend of its four texels' tests.
//! Outside the map, and behind a perspective map's centre, a point is lit.
//!
//! PCF's taps reach up to (size + 1)/2 texels from the point, where a
//! receiver sloped to the light lies deeper or shallower than at the point
//! by its slope times the distance: tested at the point's own depth, the
//! receiver shadows itself (acne) on every sloped lit surface, which the
//! raster's slope-scaled offset (sized for the half texel of a nearest
//! lookup) does not cover (measured: 12.6% of the lit pixels of
//! stairs_low_sun at 320x240 with `PCF(size=3)`, 0.01% without a filter).
//! So each texel of the box is tested at the depth of the receiver's
//! tangent plane there (receiver plane depth bias, Isidoro 2006, "Shadow
//! Mapping: GPU-based Tips and Techniques", GDC):
//! d_k = d + (∂d/∂x) ox_k + (∂d/∂y) oy_k, (ox_k, oy_k) the texel centre's
//! offset from the point, the gradient from the point's normal
//! (`receiver_gradient`). A nearest lookup keeps the point's depth.

use super::config::{DepthBias, Pcf};
use super::raster::{DepthMap, Distribution};
use crate::geom::light::MapGrid;
use crate::geom::plane_gradient::plane_gradient;
use crate::geom::shadow_projection::ShadowProjection;
use crate::methods::pcf::Border;
use glam::DVec3;

/// A shadow map ready to be looked up.
pub struct Lookup<'a> {
    map: &'a DepthMap,
    proj: &'a ShadowProjection,
    bias: DepthBias,
    filter: Option<Pcf>,
    /// The map's texel grid, as `pcf.rs` reads it.
    grid: Option<MapGrid>,
}

impl<'a> Lookup<'a> {
    pub fn new(
        map: &'a DepthMap,
        proj: &'a ShadowProjection,
        bias: DepthBias,
        filter: Option<Pcf>,
    ) -> Self {
        let grid = MapGrid::new(map.width, map.height, [1.0, 1.0]).ok();
        Lookup {
            map,
            proj,
            bias,
            filter,
            grid,
        }
    }
    /// Whether texel (i, j) passes at depth d (out of the map: lit).
    #[inline]
    fn pass(&self, i: i64, j: i64, d: f32) -> f32 {
        let m = self.map;
        if i < 0 || j < 0 || i >= m.width as i64 || j >= m.height as i64 {
            return 1.0;
        }
        let k = j as usize * m.width + i as usize;
        let limit = match (self.bias, &m.second) {
            (DepthBias::Midpoint, Some(s)) => 0.5 * (m.nearest[k] + s[k]),
            _ => m.nearest[k],
        };
        (d <= limit) as u8 as f32
    }

    /// The visibility of world point `p` whose receiver's depth gradient
    /// (per texel, `receiver_gradient`) is `gradient`.
    pub fn visibility(&self, p: DVec3, gradient: [f32; 2]) -> f32 {
        let Query::At { x, y, depth: d } =
            query(self.proj, self.bias, self.map.width, self.map.height, p)
        else {
            return 1.0;
        };
        match (self.filter, &self.grid) {
            (Some(pcf), Some(grid)) => {
                let w = self.map.width as i64;
                let plane = TapPlane::new(x, y, d, gradient, pcf.size);
                // pcf.rs's texel i covers [i, i + 1]: its centre is ours + 1/2.
                pcf.filter(grid, x + 0.5, y + 0.5, Border::Constant(1.0), |k| {
                    let (i, j) = (k as i64 % w, k as i64 / w);
                    self.pass(i, j, plane.depth(i, j))
                })
            }
            _ => self.pass(x.round() as i64, y.round() as i64, d),
        }
    }
}

/// The receiver's tangent plane over a PCF box, in the f32 operations the
/// GPU twin repeats (shadow_mapping.wgsl's `sm_lookup`): the offsets of the
/// box's first texel (`box_origin`) from the point, rounded once, then
/// whole texels added.
#[derive(Debug, Clone, Copy)]
pub struct TapPlane {
    pub i0: i64,
    pub j0: i64,
    pub ox: f32,
    pub oy: f32,
    pub depth: f32,
    pub gradient: [f32; 2],
}

impl TapPlane {
    pub fn new(x: f64, y: f64, depth: f32, gradient: [f32; 2], size: u32) -> Self {
        let (i0, j0) = (box_origin(x, size), box_origin(y, size));
        TapPlane {
            i0: i0 as i64,
            j0: j0 as i64,
            ox: (i0 - x) as f32,
            oy: (j0 - y) as f32,
            depth,
            gradient,
        }
    }

    /// The depth tested at texel (i, j).
    #[inline]
    pub fn depth(&self, i: i64, j: i64) -> f32 {
        let ox = self.ox + (i - self.i0) as f32;
        let oy = self.oy + (j - self.j0) as f32;
        self.depth + self.gradient[0] * ox + self.gradient[1] * oy
    }
}

/// The first texel of a PCF box of `size` taps around continuous texel
/// coordinate `x` (pcf.rs's box [x + 1/2 - size/2, x + 1/2 + size/2] in its
/// texel-covers-[i, i+1] coordinates: from floor of its start on).
pub fn box_origin(x: f64, size: u32) -> f64 {
    (x + 0.5 - 0.5 * size.max(1) as f64).floor()
}

/// The depth gradient (∂d/∂x, ∂d/∂y), per texel, of the receiver's tangent
/// plane at world point `p` of normal `n` in a (width, height) map of
/// `proj`, d the depth the lookup tests (`geom::plane_gradient`; the plane
/// is flat and a perspective map's depth smooth over the step, 1e-4 of the
/// point's distance from the origin plus one). Zero where the plane is
/// edge-on to the map or the steps project nowhere.
pub fn receiver_gradient(
    proj: &ShadowProjection,
    bias: DepthBias,
    (width, height): (usize, usize),
    p: DVec3,
    n: DVec3,
) -> [f32; 2] {
    let at =
        |q: DVec3| query_f64(proj, bias, width, height, q).map(|(x, y, d)| DVec3::new(x, y, d));
    plane_gradient(at, p, n, 1e-4 * (1.0 + p.length())).map_or([0.0; 2], |g| g.map(|v| v as f32))
}

/// `query`'s texel position and depth in f64 (None where it is lit).
fn query_f64(
    proj: &ShadowProjection,
    bias: DepthBias,
    width: usize,
    height: usize,
    p: DVec3,
) -> Option<(f64, f64, f64)> {
    let q = proj.project(p);
    if !(q.w > 0.0) || !q.u.is_finite() || !q.v.is_finite() {
        return None;
    }
    let depth = match bias.distribution() {
        Distribution::Hyperbolic => q.hyperbolic,
        Distribution::Linear => q.linear,
    };
    Some((
        (q.u + 1.0) * 0.5 * width as f64 - 0.5,
        (1.0 - q.v) * 0.5 * height as f64 - 0.5,
        depth,
    ))
}

/// Where a point looks its map up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Query {
    /// Behind a perspective map's centre (or projected to no finite
    /// position): lit.
    Lit,
    /// Continuous texel coordinates (texel [j, i] centred at (i, j)) and the
    /// depth tested, in the map's distribution.
    At { x: f64, y: f64, depth: f32 },
}

/// The projection of world point `p` into a (width, height) map of `proj`
/// (in f64, shared by both backends' lookups).
pub fn query(
    proj: &ShadowProjection,
    bias: DepthBias,
    width: usize,
    height: usize,
    p: DVec3,
) -> Query {
    match query_f64(proj, bias, width, height, p) {
        Some((x, y, depth)) => Query::At {
            x,
            y,
            depth: depth as f32,
        },
        None => Query::Lit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::shadow_mapping::config::Real;

    /// A map over u in [-1, 1] whose left half holds depth 0 (an occluder)
    /// and right half 1 (nothing nearer than the receiver at 0.5).
    fn half_plane(n: usize) -> (DepthMap, ShadowProjection) {
        let nearest = (0..n * n)
            .map(|k| if (k % n) < n / 2 { 0.0 } else { 1.0 })
            .collect();
        let map = DepthMap {
            width: n,
            height: n,
            nearest,
            second: None,
            triangles: 0,
        };
        let pts = [DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, 1.0)];
        // Light travelling +z; u along x, v along y.
        let proj = ShadowProjection::orthographic(DVec3::Z, DVec3::X, DVec3::Y, &pts).unwrap();
        (map, proj)
    }

    fn at(l: &Lookup, texel_x: f64, n: usize) -> f32 {
        // World x of continuous texel coordinate texel_x (centre at i).
        let x = (texel_x + 0.5) / n as f64 * 2.0 - 1.0;
        l.visibility(DVec3::new(x, 0.01, 0.5), [0.0; 2])
    }

    #[test]
    fn the_nearest_texel_decides_without_a_filter() {
        let n = 16;
        let (map, proj) = half_plane(n);
        let bias = DepthBias::Constant {
            constant: Real(0.0),
        };
        let l = Lookup::new(&map, &proj, bias, None);
        assert_eq!(at(&l, 7.0, n), 0.0);
        assert_eq!(at(&l, 8.0, n), 1.0);
        assert_eq!(at(&l, 7.6, n), 1.0);
    }

    #[test]
    fn pcf_ramps_over_size_texels() {
        let n = 32;
        let (map, proj) = half_plane(n);
        let bias = DepthBias::Constant {
            constant: Real(0.0),
        };
        for size in [1u32, 3] {
            let l = Lookup::new(&map, &proj, bias, Some(Pcf { size }));
            // The edge lies between texels 15 and 16 (at 15.5): the ramp is
            // centred there and spans `size` texels.
            let w = size as f64;
            assert!((at(&l, 15.5, n) - 0.5).abs() < 1e-6);
            assert_eq!(at(&l, 15.5 - 0.5 * w - 0.01, n), 0.0);
            assert_eq!(at(&l, 15.5 + 0.5 * w + 0.01, n), 1.0);
            let quarter = at(&l, 15.5 + 0.25 * w, n);
            assert!(quarter > 0.5 && quarter < 1.0, "{quarter}");
        }
    }

    /// A map of a receiver tilted to the light (z = 0.5 + 0.4 x), written
    /// exactly at its texel centres: PCF tested at the point's own depth
    /// shadows the receiver with itself; tested on its tangent plane, not.
    #[test]
    fn pcf_on_the_receiver_plane_does_not_shadow_a_tilted_receiver() {
        let n = 64;
        let (mut map, proj) = half_plane(n);
        let bias = DepthBias::Constant {
            constant: Real(0.0),
        };
        let world = |t: f64| (t + 0.5) / n as f64 * 2.0 - 1.0;
        let plane = |x: f64, y: f64| DVec3::new(x, y, 0.5 + 0.4 * x);
        let depth_at = |q: DVec3| match query(&proj, bias, n, n, q) {
            Query::At { depth, .. } => depth,
            Query::Lit => panic!("{q} is on the map"),
        };
        // A sliver over each texel's exact depth: what the raster's offset
        // gives a nearest lookup.
        map.nearest = (0..n * n)
            .map(|k| {
                let d = depth_at(plane(world((k % n) as f64), world((k / n) as f64)));
                d + 1e-6
            })
            .collect();
        let g = receiver_gradient(
            &proj,
            bias,
            (n, n),
            plane(0.1, 0.2),
            DVec3::new(-0.4, 0.0, 1.0),
        );
        // The gradient is the map's own step per texel along x, none along y.
        let step = map.nearest[n * 10 + 33] - map.nearest[n * 10 + 32];
        assert!((g[0] - step).abs() < 1e-4 * step.abs(), "{g:?} vs {step}");
        assert!(g[1].abs() < 1e-6, "{g:?}");
        let l = Lookup::new(&map, &proj, bias, Some(Pcf { size: 3 }));
        let (mut acne, mut planar) = (0, 0);
        for s in 0..200 {
            let (x, y) = (
                -0.8 + 1.6 * (s as f64 * 0.618).fract(),
                -0.8 + 1.6 * (s as f64 * 0.377).fract(),
            );
            let p = plane(x, y);
            let g = receiver_gradient(&proj, bias, (n, n), p, DVec3::new(-0.4, 0.0, 1.0));
            acne += (l.visibility(p, [0.0; 2]) < 1.0) as u32;
            planar += (l.visibility(p, g) < 1.0) as u32;
        }
        assert!(acne > 50, "{acne} of 200 shadowed at the point's depth");
        assert_eq!(planar, 0, "shadowed on the tangent plane");
        // An edge-on receiver has no plane to follow.
        let edge_on = receiver_gradient(&proj, bias, (n, n), plane(0.0, 0.0), DVec3::X);
        assert_eq!(edge_on, [0.0; 2]);
    }

    #[test]
    fn midpoint_tests_halfway_between_the_layers() {
        let n = 4;
        let (mut map, proj) = half_plane(n);
        map.nearest = vec![0.2; n * n];
        let mut second = vec![0.6; n * n];
        second[0] = f32::INFINITY;
        map.second = Some(second);
        let l = Lookup::new(&map, &proj, DepthBias::Midpoint, None);
        // Depth 0.5 > (0.2 + 0.6)/2: shadowed.
        assert_eq!(l.visibility(DVec3::new(0.1, 0.1, 0.5), [0.0; 2]), 0.0);
        // At depth 0.3 it is lit.
        assert_eq!(l.visibility(DVec3::new(0.1, 0.1, 0.3), [0.0; 2]), 1.0);
        // Texel 0 has a single surface: never shadowed.
        assert_eq!(l.visibility(DVec3::new(-0.9, 0.9, 0.9), [0.0; 2]), 1.0);
    }
}
