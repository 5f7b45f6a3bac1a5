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

use super::config::{DepthBias, Pcf};
use super::raster::{DepthMap, Distribution};
use crate::geom::light::MapGrid;
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

    /// The visibility of world point `p`.
    pub fn visibility(&self, p: DVec3) -> f32 {
        let Query::At { x, y, depth: d } =
            query(self.proj, self.bias, self.map.width, self.map.height, p)
        else {
            return 1.0;
        };
        match (self.filter, &self.grid) {
            (Some(pcf), Some(grid)) => {
                let w = self.map.width as i64;
                // pcf.rs's texel i covers [i, i + 1]: its centre is ours + 1/2.
                pcf.filter(grid, x + 0.5, y + 0.5, Border::Constant(1.0), |k| {
                    self.pass(k as i64 % w, k as i64 / w, d)
                })
            }
            _ => self.pass(x.round() as i64, y.round() as i64, d),
        }
    }
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
    let q = proj.project(p);
    if !(q.w > 0.0) || !q.u.is_finite() || !q.v.is_finite() {
        return Query::Lit;
    }
    let depth = match bias.distribution() {
        Distribution::Hyperbolic => q.hyperbolic,
        Distribution::Linear => q.linear,
    } as f32;
    Query::At {
        x: (q.u + 1.0) * 0.5 * width as f64 - 0.5,
        y: (1.0 - q.v) * 0.5 * height as f64 - 0.5,
        depth,
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
        l.visibility(DVec3::new(x, 0.01, 0.5))
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
        assert_eq!(l.visibility(DVec3::new(0.1, 0.1, 0.5)), 0.0);
        // At depth 0.3 it is lit.
        assert_eq!(l.visibility(DVec3::new(0.1, 0.1, 0.3)), 1.0);
        // Texel 0 has a single surface: never shadowed.
        assert_eq!(l.visibility(DVec3::new(-0.9, 0.9, 0.9)), 1.0);
    }
}
