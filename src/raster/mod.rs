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
//!
//! The code is split by job: `geom/clip.rs` holds the clip planes and
//! Sutherland-Hodgman clipping, `setup.rs` the projection, clipping and
//! snapping of triangles into `SetupTri`, `scan.rs` the bands and the scan of
//! one triangle, `layers.rs` the binning by band and the depth layers
//! (nearest, farthest, peeling), and `depth_plane.rs` the f32 form of 1/Z.

pub(crate) mod depth_plane;
mod edge;
mod layers;
mod scan;
mod setup;

pub use layers::{rasterize, DepthLayers, Prepared};

use glam::DVec3;
// For the GPU backend, which uploads the CPU's set-up triangles and peels
// with the same gap, and the planner, which counts layers with it.
pub(crate) use layers::PEEL_GAP;
#[cfg(feature = "gpu")]
pub(crate) use setup::{setup_triangles, SetupTri};

/// Clip distance for rasterization: a tiny fraction of the scene's depth range,
/// so that geometry touching the light's plane keeps finite 1/Z.
pub fn near_plane<'a>(verts: impl IntoIterator<Item = &'a DVec3>) -> f64 {
    let far = verts.into_iter().fold(0f64, |m, q| m.max(q.z.abs()));
    (far * 1e-9).max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::scan::raster_tri;
    use super::setup::Projector;
    use super::*;
    use crate::geom::light::MapGrid;
    use glam::DVec3;

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
