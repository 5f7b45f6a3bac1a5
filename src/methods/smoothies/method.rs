//! Smoothies behind the methods' interface (`ShadowMethod`): the front
//! occluder layer is the shadow map (step 1), the occluder triangles give
//! the silhouette. The pipelines hand the triangles over unindexed; the
//! silhouette welds corners on their exact position (`silhouette.rs`), and
//! corners shared in the user's mesh are bit-identical after the same
//! transform, so the soup's adjacency is the mesh's.

use super::{Falloff, Smoothies};
use crate::geom::plane_gradient::Plane;
use crate::methods::kernel::Kernel;
use crate::methods::shadow_mapping::config::Real;
use crate::methods::{EyePoints, Input, LightPoint, ShadowInputs, ShadowMethod};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Triangle soup -> a mesh of three corners per face (welded later).
pub(crate) fn soup(tris: &[[Vec3; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let verts = tris.iter().flatten().map(|c| c.as_dvec3()).collect();
    let faces = (0..tris.len() as u32)
        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    (verts, faces)
}

impl Smoothies {
    /// Points shaded against the occluders of `inputs`, given as an
    /// indexed mesh. The paper's shadow map holds the receivers too (its
    /// depth r behind a smoothie sizes the penumbra): where the receiver
    /// map shares the occluder grid (a light-view map) it is merged in;
    /// in the eye view every mesh is an occluder, so the front layer is
    /// already the whole scene, and each point is tested on its tangent
    /// plane `planes[i]` (`lookup.rs`; empty: none).
    pub fn shade(
        &self,
        inputs: &ShadowInputs,
        verts: &[DVec3],
        faces: &[[u32; 3]],
        points: &[LightPoint],
        planes: &[Plane],
    ) -> Vec<f32> {
        let front = inputs.occluder_layers.first().copied().unwrap_or(&[]);
        let og = &inputs.occluder_grid;
        if front.len() != og.len() {
            return vec![1.0; points.len()];
        }
        let merged;
        let map = if inputs.receiver.len() == front.len() && inputs.grid == *og {
            merged = super::shadow_map(front, inputs.receiver);
            &merged[..]
        } else {
            front
        };
        let buffer = self.buffer(og, inputs.light_shape, map, verts, faces);
        self.visibility_points(og, map, &buffer, points, planes)
    }

    fn welded(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let (verts, faces) = soup(inputs.occluder_triangles.unwrap_or(&[]));
        self.shade(inputs, &verts, &faces, points, &[])
    }
}

/// The kernel a resolved `SmoothiesConfig` runs (`kernel.rs`): `Smoothies`
/// with its width as a hashable `Real`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SmoothiesKernel {
    pub width: Real,
    pub falloff: Falloff,
}

impl Kernel for SmoothiesKernel {
    /// The front layer (the shadow map) and the occluders' silhouette.
    const READS: &'static [Input] = &[Input::OccluderLayers, Input::OccluderTriangles];
    /// The tent's taps reach texels beside the point's.
    const TESTS_PLANES: bool = true;
    /// The falloff reads the depth of the receiver behind each silhouette
    /// from the map (without the floor there, its error on contact_boxes
    /// went from under 0.1 to 0.26).
    const READS_EVERY_FACE: bool = true;

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        Box::new(Smoothies {
            width: self.width.0,
            falloff: self.falloff,
        })
    }
}

impl ShadowMethod for Smoothies {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        let g = &inputs.grid;
        let points: Vec<LightPoint> = (0..g.len())
            .into_par_iter()
            .map(|k| LightPoint {
                x: g.x_of(k % g.width) as f32,
                y: g.y_of(k / g.width) as f32,
                z: inputs.receiver[k],
            })
            .collect();
        self.welded(inputs, &points)
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        self.welded(inputs, points)
    }

    /// Every mesh is an occluder: its silhouette straight from the mesh,
    /// each point tested on its tangent plane. No weights.
    fn visibility_eye(
        &self,
        inputs: &ShadowInputs,
        eye: &EyePoints,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        let v = self.shade(inputs, eye.verts, eye.faces, eye.points, eye.planes);
        (v, None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light_shape::LightShape;

    #[test]
    fn a_soup_has_the_silhouette_of_its_indexed_mesh() {
        // A quad as two triangles: indexed, and as a soup of six corners.
        let v = [
            DVec3::new(-0.3, -0.3, 1.0),
            DVec3::new(0.3, -0.3, 1.0),
            DVec3::new(0.3, 0.3, 1.0),
            DVec3::new(-0.3, 0.3, 1.0),
        ];
        let faces = [[0u32, 1, 2], [0, 2, 3]];
        let tris: Vec<[Vec3; 3]> = faces
            .iter()
            .map(|f| f.map(|i| v[i as usize].as_vec3()))
            .collect();
        let (sv, sf) = soup(&tris);
        assert_eq!((sv.len(), sf.len()), (6, 2));
        let grid = crate::geom::light::MapGrid::new(32, 32, [0.5, 0.5]).unwrap();
        let front: Vec<f32> = (0..grid.len()).map(|_| f32::INFINITY).collect();
        let s = Smoothies {
            width: 1.0,
            falloff: super::super::Falloff::Linear,
        };
        let a = s.buffer(
            &grid,
            LightShape::rect([0.2, 0.2]),
            &front,
            &v.map(|p| p.as_vec3().as_dvec3()),
            &faces,
        );
        let b = s.buffer(&grid, LightShape::rect([0.2, 0.2]), &front, &sv, &sf);
        // Four boundary edges either way (the shared diagonal is no silhouette).
        assert_eq!(a.stats.silhouette_edges, 4);
        assert_eq!(a, b);
    }
}
