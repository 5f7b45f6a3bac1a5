//! The eye view's G-buffer: the first surface each pixel sees.
//!
//! On the CPU every mesh is rasterized from the camera (`raster/`, the
//! light-view maps' rasterizer: exact edge functions at pixel centres, a tie
//! rule on shared edges, 1/Z interpolated) keeping the nearest face per
//! pixel. The camera's frame is a light frame at the eye, (r, u', f); a
//! principal point off the centre is a shear, `X' = X - dx Z`,
//! `Y' = Y - dy Z` with `dx = ((W-1)/2 - cx)/f_px`, `dy = (cy - (H-1)/2)/f_px`,
//! which puts pixel [j, i]'s centre on the centred grid's texel [j, i]
//! (tangent half-extents W/(2 f_px), H/(2 f_px)). The GPU casts the same
//! pixel-centre rays through a BVH (`camera_bvh`, `pixel_ray`). Either way
//! the hit is then recomputed in f64 on the face's plane along the pixel's
//! ray (`from_hits`), so positions keep f64 precision however far the scene
//! is from the origin, and agree with Mitsuba's first hits (the same
//! pixel-centre rays) except where a pixel centre grazes an edge.

use crate::error::{Error, Result};
use crate::geom::camera::Camera;
use crate::geom::light::MapGrid;
use crate::geom::mesh::MeshRef;
use crate::methods::exact::Bvh;
use crate::raster::Prepared;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// What each pixel sees, row-major (H, W).
#[derive(Debug, Clone)]
pub struct GBuffer {
    pub width: usize,
    pub height: usize,
    /// Distance along the optical axis; inf where no surface.
    pub depth: Vec<f32>,
    /// World position; NaN where no surface.
    pub position: Vec<[f64; 3]>,
    /// Unit geometric normal facing the camera; 0 where no surface.
    pub normal: Vec<[f32; 3]>,
    /// Index of the mesh hit, -1 where none.
    pub mesh_id: Vec<i32>,
    /// Index of the face hit within its mesh; `NO_FACE` where none.
    pub face: Vec<u32>,
    /// The hit's barycentric coordinates (b1, b2) on that face: the point
    /// is `(1 - b1 - b2) p0 + b1 p1 + b2 p2` of the face's corners in order.
    pub bary: Vec<[f32; 2]>,
}

/// `GBuffer::face` where a pixel sees no surface.
pub const NO_FACE: u32 = u32::MAX;

impl GBuffer {
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Flat indices of the pixels that see a surface.
    pub fn hits(&self) -> Vec<usize> {
        (0..self.len())
            .into_par_iter()
            .filter(|&k| self.mesh_id[k] >= 0)
            .collect()
    }
}

/// Every mesh's triangles with the mesh each came from.
pub struct SceneTriangles {
    /// World-space corners (f64).
    pub corners: Vec<[DVec3; 3]>,
    pub mesh_of: Vec<i32>,
    /// The same triangles indexed: every mesh's vertices in one list, and
    /// the faces into it (the rasterizers set up each vertex once).
    pub vertices: Vec<DVec3>,
    pub faces: Vec<[u32; 3]>,
    /// Each mesh's first triangle in these lists.
    pub first_face: Vec<u32>,
}

impl SceneTriangles {
    /// Checks the meshes (named `meshes[k]`) and gathers their triangles.
    pub fn new(meshes: &[MeshRef]) -> Result<SceneTriangles> {
        if meshes.iter().all(|m| m.is_empty()) {
            return Err(Error::invalid("meshes", "the scene has no triangles"));
        }
        if meshes.len() > i32::MAX as usize {
            return Err(Error::invalid("meshes", "too many meshes"));
        }
        if meshes.iter().map(|m| m.vertices.len()).sum::<usize>() > u32::MAX as usize {
            return Err(Error::invalid("meshes", "more than 2^32 vertices in all"));
        }
        // Every list filled in parallel in place: on 2 000 000 triangles a
        // first call's `first_hits` lap (which holds this) went from 281 to
        // 137 ms against one thread filling them.
        let nf = meshes.iter().map(|m| m.faces.len()).sum();
        let nv = meshes.iter().map(|m| m.vertices.len()).sum();
        let (mut corners, mut mesh_of) = (Vec::with_capacity(nf), Vec::with_capacity(nf));
        let (mut vertices, mut faces) = (Vec::with_capacity(nv), Vec::with_capacity(nf));
        let mut first_face = Vec::with_capacity(meshes.len());
        for (k, m) in meshes.iter().enumerate() {
            first_face.push(faces.len() as u32);
            m.validate(&format!("meshes[{k}]"))?;
            corners.par_extend(
                m.faces
                    .par_iter()
                    .map(|f| f.map(|i| DVec3::from_array(m.vertices[i as usize]))),
            );
            mesh_of.par_extend(rayon::iter::repeat_n(k as i32, m.faces.len()));
            let first = vertices.len() as u32;
            faces.par_extend(m.faces.par_iter().map(|f| f.map(|i| first + i)));
            vertices.par_extend(m.vertices.par_iter().map(|v| DVec3::from_array(*v)));
        }
        Ok(SceneTriangles {
            corners,
            mesh_of,
            vertices,
            faces,
            first_face,
        })
    }

    /// Every vertex, for bounds.
    pub fn points(&self) -> impl Iterator<Item = DVec3> + Clone + '_ {
        self.vertices.iter().copied()
    }
}

/// The BVH the camera rays are cast against: every triangle relative to
/// the eye, in f32 (the GPU twin traverses the same nodes).
pub fn camera_bvh(camera: &Camera, scene: &SceneTriangles) -> Bvh {
    let eye = camera.eye;
    Bvh::build(
        scene
            .corners
            .par_iter()
            .map(|t| t.map(|c| (c - eye).as_vec3()))
            .collect(),
    )
}

/// The f32 direction of pixel k's ray, as both backends cast it.
#[inline]
pub fn pixel_ray(camera: &Camera, k: usize) -> Vec3 {
    camera
        .pixel_direction(k % camera.width, k / camera.width)
        .as_vec3()
}

/// The nearest face at every pixel centre, rasterized from the camera.
pub fn rasterized_hits(camera: &Camera, scene: &SceneTriangles) -> Vec<Option<u32>> {
    let (w, h, f) = (camera.width as f64, camera.height as f64, camera.focal);
    let dx = ((w - 1.0) / 2.0 - camera.cx) / f;
    let dy = (camera.cy - (h - 1.0) / 2.0) / f;
    let verts: Vec<DVec3> = scene
        .vertices
        .par_iter()
        .map(|&p| {
            let d = p - camera.eye;
            let z = d.dot(camera.forward);
            DVec3::new(d.dot(camera.right) - dx * z, d.dot(camera.up) - dy * z, z)
        })
        .collect();
    let faces = &scene.faces;
    // The camera's validated grid: its tangents are within MAX_TANGENT.
    let grid = match MapGrid::new(camera.width, camera.height, [w / (2.0 * f), h / (2.0 * f)]) {
        Ok(g) => g,
        Err(_) => return vec![None; camera.width * camera.height],
    };
    let near = crate::raster::near_plane(&verts);
    Prepared::with_faces(&grid, &verts, faces, near)
        .nearest_faces()
        .1
}

/// What each pixel of `camera` sees of the scene.
pub fn first_hits(camera: &Camera, scene: &SceneTriangles) -> GBuffer {
    from_hits(camera, scene, &rasterized_hits(camera, scene))
}

/// The G-buffer from the triangle each pixel's ray hit first (`None`: no
/// surface): position, normal and depth in f64 on the triangle's plane.
pub fn from_hits(camera: &Camera, scene: &SceneTriangles, hit: &[Option<u32>]) -> GBuffer {
    let (w, h) = (camera.width, camera.height);
    let n = w * h;
    assert_eq!(hit.len(), n, "one hit per pixel");
    let xs: Vec<f64> = (0..w).map(|i| camera.pixel_tangent(i, 0).0).collect();
    // Every pixel of every buffer is written once, by the rows in parallel,
    // into capacity nothing filled first: filling them with the misses'
    // values (or zeroing a reused block) wrote 116 MB on one thread at
    // 1920x1080 before the rows wrote them again.
    let (mut depth, mut position) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut normal, mut mesh_id) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut face, mut bary) = (Vec::with_capacity(n), Vec::with_capacity(n));
    depth.spare_capacity_mut()[..n]
        .par_chunks_mut(w)
        .zip(position.spare_capacity_mut()[..n].par_chunks_mut(w))
        .zip(normal.spare_capacity_mut()[..n].par_chunks_mut(w))
        .zip(mesh_id.spare_capacity_mut()[..n].par_chunks_mut(w))
        .zip(
            face.spare_capacity_mut()[..n]
                .par_chunks_mut(w)
                .zip(bary.spare_capacity_mut()[..n].par_chunks_mut(w)),
        )
        .zip(hit.par_chunks(w))
        .enumerate()
        .for_each(
            |(j, (((((depth, position), normal), mesh_id), (face, bary)), hit))| {
                // The pixel's ray as `Camera::pixel_direction` makes it, its
                // tangents read from the column's and the row's (same bits).
                let yu = camera.pixel_tangent(0, j).1 * camera.up;
                let mut last: Option<Face> = None;
                for (i, tri) in hit.iter().enumerate() {
                    let s = tri.and_then(|tri| {
                        let d = (camera.forward + xs[i] * camera.right + yu).normalize();
                        // Neighbouring pixels often see the same face: its
                        // plane is set up once for them.
                        let f = match last {
                            Some(f) if f.tri == tri => f,
                            _ => Face::new(scene, tri, camera.eye),
                        };
                        last = Some(f);
                        surface(camera, &f, d)
                    });
                    let s = s.unwrap_or(Surface::NONE);
                    depth[i].write(s.depth);
                    position[i].write(s.position);
                    normal[i].write(s.normal);
                    mesh_id[i].write(s.mesh);
                    face[i].write(s.face);
                    bary[i].write(s.bary);
                }
            },
        );
    // SAFETY: `hit` has n entries (asserted), so its rows cover the first n
    // slots of every buffer, and the loop above wrote each slot of each row.
    unsafe {
        depth.set_len(n);
        position.set_len(n);
        normal.set_len(n);
        mesh_id.set_len(n);
        face.set_len(n);
        bary.set_len(n);
    }
    GBuffer {
        width: w,
        height: h,
        depth,
        position,
        normal,
        mesh_id,
        face,
        bary,
    }
}

/// What pixel (i, j) sees on triangle `tri`: one pixel of the G-buffer.
struct Surface {
    depth: f32,
    position: [f64; 3],
    normal: [f32; 3],
    mesh: i32,
    face: u32,
    bary: [f32; 2],
}

impl Surface {
    /// A pixel that sees no surface.
    const NONE: Surface = Surface {
        depth: f32::INFINITY,
        position: [f64::NAN; 3],
        normal: [0.0; 3],
        mesh: -1,
        face: NO_FACE,
        bary: [0.0; 2],
    };
}

/// A face as the pixels that see it need it: what `surface` computes of
/// it alone, computed once (the same operations, so the same bits).
#[derive(Clone, Copy)]
struct Face {
    tri: u32,
    a: DVec3,
    /// b - a and c - a.
    ba: DVec3,
    ca: DVec3,
    /// The plane's normal (b - a) x (c - a), its squared length and its
    /// direction.
    nrm: DVec3,
    nn: f64,
    unit: DVec3,
    /// nrm . (a - eye): the eye's distance to the plane, times |nrm|.
    plane: f64,
    mesh: i32,
    /// Its index within its mesh.
    face: u32,
}

impl Face {
    fn new(scene: &SceneTriangles, tri: u32, eye: DVec3) -> Face {
        let [a, b, c] = scene.corners[tri as usize];
        let (ba, ca) = (b - a, c - a);
        let nrm = ba.cross(ca);
        let mesh = scene.mesh_of[tri as usize];
        Face {
            tri,
            a,
            ba,
            ca,
            nrm,
            nn: nrm.length_squared(),
            unit: nrm.normalize(),
            plane: nrm.dot(a - eye),
            mesh,
            face: tri - scene.first_face[mesh as usize],
        }
    }
}

/// The hit of the pixel's ray (unit direction `d` from the eye) on face
/// `f`'s plane, in f64; `None` where the ray runs along the plane or meets
/// it behind the eye.
#[inline]
fn surface(camera: &Camera, f: &Face, d: DVec3) -> Option<Surface> {
    let eye = camera.eye;
    let (a, nrm) = (f.a, f.nrm);
    let den = nrm.dot(d);
    // The f32 hit refined in f64 on the triangle's plane.
    let t = f.plane / den;
    if !(t.is_finite() && t > 0.0) {
        return None;
    }
    // Barycentrics of q = a + b1 (b - a) + b2 (c - a):
    // (q - a) x (c - a) = b1 N and (b - a) x (q - a) = b2 N.
    let q = eye + t * d;
    let b1 = nrm.dot((q - a).cross(f.ca)) / f.nn;
    let b2 = nrm.dot(f.ba.cross(q - a)) / f.nn;
    let unit = if den > 0.0 { -f.unit } else { f.unit };
    Some(Surface {
        depth: (t * d.dot(camera.forward)) as f32,
        position: q.to_array(),
        normal: unit.as_vec3().to_array(),
        mesh: f.mesh,
        face: f.face,
        bary: [b1 as f32, b2 as f32],
    })
}
