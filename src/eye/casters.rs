//! Which triangles can shadow a visible point (Scherzer et al. 2005, §4.1:
//! focusing; the light-view maps hold texels only where a pixel needs them).
//!
//! A triangle with the whole light strictly on one side of its plane
//! shadows nothing on that side: a segment from a point p with
//! n·(p − p0) ≥ 0 to a light point y with n·(y − p0) > 0 stays in the
//! closed half-space and meets the plane at most at p itself. So where
//! every visible point lies on the light's side of a triangle's plane, the
//! triangle neither takes texels in the occluder maps nor widens their
//! extent. The sun is a cone of directions: its whole disc must lie on the
//! plane's lit side.
//!
//! The rule is per triangle, whatever mesh it belongs to and however it is
//! wound: a floor, a wall or a ceiling built as a closed box (its faces all
//! have every visible point on their lit side) casts nothing, exactly like
//! a one-sided quad, and neither do the bottoms of objects resting on it.
//! Without it, visible ground reaching toward the light's plane widened the
//! maps' extent to tangents of 40-56 and left the occluders a few percent
//! of the texels (docs/eye_view.md); a box floor kept that, and its bottom
//! face became every texel's back layer (docs/accuracy.md).
//!
//! Cost: each triangle's plane against the points, in chunks of 64
//! consecutive pixels and groups of 64 chunks with their bounding boxes: a
//! group or chunk whose box lies on the lit side is passed over whole, and
//! a triangle stops at the first point on its dark side (most casters find
//! one in the first chunks).

use glam::DVec3;
use rayon::prelude::*;

use super::gbuffer::SceneTriangles;
use crate::geom::light_space::Light;

/// Thickness of a plane, relative to the scene's size, within which a
/// point counts as on it (f64 world coordinates: a visible point on a
/// floor lies on the floor's plane to about 1e-16 of the scene's size).
const PLANE_TOLERANCE: f64 = 1e-9;

/// Consecutive visible points per bounding box, and chunks per group.
const CHUNK: usize = 64;

/// Per triangle of `scene`, whether it can shadow one of `points` (world
/// positions of the visible pixels) under `light`.
pub(crate) fn casting_triangles(
    scene: &SceneTriangles,
    light: &Light,
    points: &[[f64; 3]],
) -> Vec<bool> {
    let chunks: Vec<Chunk> = points
        .par_chunks(CHUNK)
        .map(|c| {
            let (lo, hi) = bounds(c.iter().map(|p| DVec3::from_array(*p)));
            Chunk { lo, hi, points: c }
        })
        .collect();
    // Groups of chunks with their boxes: a triangle that casts nothing
    // (a floor's) passes over a group whole instead of over each chunk.
    let groups: Vec<(DVec3, DVec3, &[Chunk])> = chunks
        .chunks(CHUNK)
        .map(|g| {
            let (lo, hi) = bounds(g.iter().flat_map(|c| [c.lo, c.hi]));
            (lo, hi, g)
        })
        .collect();
    let (lo, hi) = bounds(
        scene
            .vertices
            .iter()
            .copied()
            .chain(groups.iter().flat_map(|g| [g.0, g.1])),
    );
    let tol = PLANE_TOLERANCE * (hi - lo).max_element().max(1e-300);
    scene
        .corners
        .par_iter()
        .with_min_len(256)
        .map(|t| {
            let c = (t[1] - t[0]).cross(t[2] - t[0]);
            let a = c.length();
            if !(a > 0.0) {
                return false; // no area: nothing to rasterize
            }
            // Orient the normal toward the light; the light must be strictly on that side.
            let Some(n) = lit_side(light, t[0], c / a, tol) else {
                return true;
            };
            let floor = n.dot(t[0]) - tol;
            groups.iter().any(|(lo, hi, chunks)| {
                least(n, *lo, *hi) < floor
                    && chunks.iter().any(|c| {
                        least(n, c.lo, c.hi) < floor
                            && c.points
                                .iter()
                                .any(|p| n.dot(DVec3::from_array(*p)) < floor)
                    })
            })
        })
        .collect()
}

/// Consecutive visible points and their bounding box.
struct Chunk<'a> {
    lo: DVec3,
    hi: DVec3,
    points: &'a [[f64; 3]],
}

/// The bounding box of `points` (empty: +inf, -inf).
fn bounds(points: impl Iterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// The least n·p over the box [lo, hi]: each axis at its low or high end.
#[inline]
fn least(n: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    n.x * if n.x >= 0.0 { lo.x } else { hi.x }
        + n.y * if n.y >= 0.0 { lo.y } else { hi.y }
        + n.z * if n.z >= 0.0 { lo.z } else { hi.z }
}

/// The plane's normal turned toward the light when the whole light lies
/// strictly on one side of the plane (through p0, normal n); None when
/// the light meets the plane.
fn lit_side(light: &Light, p0: DVec3, n: DVec3, tol: f64) -> Option<DVec3> {
    match light {
        Light::Area(l) => l.strict_side(p0, n, tol),
        Light::Sun(s) => {
            // Directions toward the sun: -s.n within its half-angles.
            let to_sun = -s.n;
            let c = n.dot(to_sun);
            let half = 0.5 * s.angular_size[0].max(s.angular_size[1]);
            let margin = half.to_radians().sin();
            if c > margin {
                Some(n)
            } else if c < -margin {
                Some(-n)
            } else {
                None
            }
        }
        // Traced whole (sphere_light.rs): every triangle may cast.
        Light::Sphere(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::AreaLight;
    use crate::geom::mesh::MeshRef;

    fn quad(y: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (
            vec![
                [-5.0, y, -5.0],
                [5.0, y, -5.0],
                [5.0, y, 5.0],
                [-5.0, y, 5.0],
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    fn tetra() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        (
            vec![
                [0.0, 1.0, 0.0],
                [0.3, 1.5, 0.0],
                [0.0, 1.5, 0.3],
                [-0.3, 1.5, -0.3],
            ],
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
        )
    }

    /// A unit square 4 above the ground, facing down.
    fn light() -> Light {
        AreaLight::rect(
            [0.0, 4.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0],
        )
        .unwrap()
        .into()
    }

    #[test]
    fn a_ground_lit_from_above_casts_nothing_and_the_object_does() {
        let (gv, gf) = quad(0.0);
        let (tv, tf) = tetra();
        let meshes = [
            MeshRef {
                vertices: &gv,
                faces: &gf,
            },
            MeshRef {
                vertices: &tv,
                faces: &tf,
            },
        ];
        let scene = SceneTriangles::new(&meshes).unwrap();
        let pts = [[1.0, 0.0, 1.0], [0.0, 1.2, 0.05]];
        // The ground's two triangles cast nothing; the tetrahedron's top
        // face (y = 1.5) has the ground point below it, on its dark side.
        let casts = casting_triangles(&scene, &light(), &pts);
        assert_eq!(&casts[..2], &[false, false]);
        assert!(casts[5]);
        assert_eq!(casts, brute_force(&scene, &pts));
        // A point below the ground (seen from underneath) can be shadowed by it.
        let below = [[1.0, -0.5, 1.0]];
        let casts = casting_triangles(&scene, &light(), &below);
        assert_eq!(&casts[..2], &[true, true]);
        assert_eq!(casts, brute_force(&scene, &below));
    }

    #[test]
    fn a_plane_the_light_straddles_casts() {
        let (gv, gf) = quad(4.0);
        let meshes = [MeshRef {
            vertices: &gv,
            faces: &gf,
        }];
        let scene = SceneTriangles::new(&meshes).unwrap();
        assert_eq!(casting_triangles(&scene, &light(), &[]), vec![true, true]);
    }

    /// A floor built as a closed box casts nothing on what stands on it,
    /// however the box is wound and placed, and a box resting on it keeps
    /// the faces that can shadow the floor (its top and sides) but not its
    /// bottom.
    #[test]
    fn a_box_floor_casts_nothing_and_a_resting_box_drops_its_bottom() {
        let floor = boxed([-5.0, -0.1, -5.0], [5.0, 0.0, 5.0]);
        let block = boxed([-0.2, 0.0, -0.2], [0.2, 0.4, 0.2]);
        // The floor wound inside out: the rule does not read the winding.
        let flipped: Vec<[u32; 3]> = floor.1.iter().map(|f| [f[0], f[2], f[1]]).collect();
        for floor_faces in [&floor.1, &flipped] {
            let meshes = [
                MeshRef {
                    vertices: &floor.0,
                    faces: floor_faces,
                },
                MeshRef {
                    vertices: &block.0,
                    faces: &block.1,
                },
            ];
            let scene = SceneTriangles::new(&meshes).unwrap();
            // Floor points around the block (one in its shadow) and on its top.
            let mut pts: Vec<[f64; 3]> = (0..200)
                .map(|k| {
                    let a = k as f64 * 0.1;
                    [0.3 + 2.0 * a.cos().abs(), 0.0, 2.0 * a.sin()]
                })
                .collect();
            pts.push([0.0, 0.4, 0.0]);
            let casts = casting_triangles(&scene, &light(), &pts);
            assert!(
                casts[..12].iter().all(|&c| !c),
                "the floor casts: {casts:?}"
            );
            let block_casts: Vec<bool> = casts[12..].to_vec();
            for (t, c) in scene.corners[12..].iter().zip(&block_casts) {
                let bottom = t.iter().all(|p| p.y == 0.0);
                assert_eq!(*c, !bottom, "{t:?}");
            }
        }
    }

    /// The rule point by point, without the chunks' boxes: a triangle
    /// casts when the light is not strictly on one side of its plane, or a
    /// point lies strictly on the other side.
    fn brute_force(scene: &SceneTriangles, pts: &[[f64; 3]]) -> Vec<bool> {
        scene
            .corners
            .iter()
            .map(|t| {
                let c = (t[1] - t[0]).cross(t[2] - t[0]);
                match lit_side(&light(), t[0], c.normalize(), 1e-12) {
                    None => true,
                    Some(n) => pts
                        .iter()
                        .any(|p| n.dot(DVec3::from_array(*p) - t[0]) < -1e-9),
                }
            })
            .collect()
    }

    /// Many points in many chunks: the boxes pass over nothing the points
    /// would catch.
    #[test]
    fn the_chunks_boxes_agree_with_every_point() {
        let (tv, tf) = tetra();
        let (gv, gf) = quad(0.0);
        let meshes = [
            MeshRef {
                vertices: &tv,
                faces: &tf,
            },
            MeshRef {
                vertices: &gv,
                faces: &gf,
            },
        ];
        let scene = SceneTriangles::new(&meshes).unwrap();
        // Points on a spiral around the tetrahedron and on the ground.
        let pts: Vec<[f64; 3]> = (0..6000)
            .map(|k| {
                let a = k as f64 * 0.37;
                let r = 0.05 + 0.002 * k as f64;
                [
                    r * a.cos(),
                    1.0 + 0.4 * (a * 0.5).sin() * (k % 3) as f64 * 0.5,
                    r * a.sin(),
                ]
            })
            .collect();
        for n in [1, 10, 63, 64, 65, 1000, 4096, 4097, 6000] {
            assert_eq!(
                casting_triangles(&scene, &light(), &pts[..n]),
                brute_force(&scene, &pts[..n]),
                "{n} points"
            );
        }
    }

    /// An axis-aligned closed box from `lo` to `hi`, 12 triangles.
    fn boxed(lo: [f64; 3], hi: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let v = (0..8)
            .map(|k| {
                [
                    if k & 4 != 0 { hi[0] } else { lo[0] },
                    if k & 2 != 0 { hi[1] } else { lo[1] },
                    if k & 1 != 0 { hi[2] } else { lo[2] },
                ]
            })
            .collect();
        let f = vec![
            [0, 1, 3],
            [0, 3, 2],
            [4, 6, 7],
            [4, 7, 5],
            [0, 4, 5],
            [0, 5, 1],
            [2, 3, 7],
            [2, 7, 6],
            [0, 2, 6],
            [0, 6, 4],
            [1, 5, 7],
            [1, 7, 3],
        ];
        (v, f)
    }
}
