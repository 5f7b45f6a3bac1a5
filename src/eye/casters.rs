//! Which meshes can shadow a visible point (Scherzer et al. 2005, §4.1:
//! focusing; the light-view maps hold texels only where a pixel needs them).
//!
//! A planar mesh with the whole light strictly on one side of its plane
//! shadows nothing on that side: a segment from a point p with
//! n·(p − p0) ≥ 0 to a light point y with n·(y − p0) > 0 stays in the
//! closed half-space and meets the plane at most at p itself. So where
//! every visible point off the mesh lies on the light's side (a ground or
//! a wall lit on its visible side), the mesh neither takes texels in the
//! occluder maps nor widens their extent. The sun is a cone of directions:
//! its whole disc must lie on the plane's lit side.
//!
//! Without this, visible ground reaching toward the light's plane widened
//! the maps' extent to tangents of 40-56 and left the occluders a few
//! percent of the texels (docs/eye_view.md).

use glam::DVec3;

use super::gbuffer::SceneTriangles;
use crate::geom::light_space::Light;

/// A plane's thickness, relative to its mesh's size, within which its
/// vertices count as coplanar (f64 world coordinates).
const PLANE_TOLERANCE: f64 = 1e-9;

/// Per mesh, whether it can shadow one of `points` (world positions of the
/// visible pixels, `point_mesh` their meshes) under `light`.
pub(crate) fn casters(
    scene: &SceneTriangles,
    light: &Light,
    points: &[[f64; 3]],
    point_mesh: &[i32],
) -> Vec<bool> {
    let meshes = scene
        .mesh_of
        .iter()
        .map(|&m| m as usize + 1)
        .max()
        .unwrap_or(0);
    let mut planes: Vec<Option<(DVec3, DVec3, f64)>> = vec![None; meshes];
    // The plane of each mesh's largest face.
    let mut area = vec![0f64; meshes];
    for (t, &m) in scene.corners.iter().zip(&scene.mesh_of) {
        let m = m as usize;
        let c = (t[1] - t[0]).cross(t[2] - t[0]);
        let a = c.length();
        if a > area[m] {
            area[m] = a;
            planes[m] = Some((t[0], c / a, 0.0));
        }
    }
    // Planar: every corner within the tolerance of that plane (and the
    // mesh's size, which scales the tolerance).
    let mut size = vec![0f64; meshes];
    for (t, &m) in scene.corners.iter().zip(&scene.mesh_of) {
        let m = m as usize;
        if let Some((p0, n, off)) = planes[m] {
            let d = t.iter().map(|c| n.dot(*c - p0).abs()).fold(off, f64::max);
            size[m] = t.iter().map(|c| (*c - p0).length()).fold(size[m], f64::max);
            planes[m] = Some((p0, n, d));
        }
    }
    (0..meshes)
        .map(|m| {
            let Some((p0, n, off)) = planes[m] else {
                return true; // no area: nothing to rasterize anyway
            };
            let tol = PLANE_TOLERANCE * size[m].max(1e-300);
            if off > tol {
                return true; // not planar
            }
            // Orient n toward the light; the light must be strictly on that side.
            let n = match lit_side(light, p0, n, tol) {
                Some(n) => n,
                None => return true,
            };
            points
                .iter()
                .zip(point_mesh)
                .any(|(p, &pm)| pm as usize != m && n.dot(DVec3::from_array(*p) - p0) < -tol)
        })
        .collect()
}

/// The plane's normal turned toward the light when the whole light lies
/// strictly on one side of the plane (through p0, normal n); None when
/// the light meets the plane.
fn lit_side(light: &Light, p0: DVec3, n: DVec3, tol: f64) -> Option<DVec3> {
    match light {
        Light::Rect(l) => {
            let d = l.corners().map(|c| n.dot(c - p0));
            if d.iter().all(|&x| x > tol) {
                Some(n)
            } else if d.iter().all(|&x| x < -tol) {
                Some(-n)
            } else {
                None
            }
        }
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::RectLight;
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

    fn light() -> Light {
        Light::Rect(RectLight {
            center: DVec3::new(0.0, 4.0, 0.0),
            u: DVec3::X,
            v: DVec3::Z,
            n: -DVec3::Y,
            size: [1.0, 1.0],
        })
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
        assert_eq!(casters(&scene, &light(), &pts, &[0, 1]), vec![false, true]);
        // A point below the ground (seen from underneath) can be shadowed by it.
        let below = [[1.0, -0.5, 1.0]];
        assert_eq!(casters(&scene, &light(), &below, &[1]), vec![true, true]);
    }

    #[test]
    fn a_plane_the_light_straddles_casts() {
        let (gv, gf) = quad(4.0);
        let meshes = [MeshRef {
            vertices: &gv,
            faces: &gf,
        }];
        let scene = SceneTriangles::new(&meshes).unwrap();
        assert_eq!(casters(&scene, &light(), &[], &[]), vec![true]);
    }
}
