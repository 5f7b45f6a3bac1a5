//! Smoothies behind the methods' interface (`ShadowMethod`): the front
//! occluder layer is the shadow map (step 1), the occluder triangles give
//! the silhouette. The pipelines hand the triangles over unindexed, so
//! their corners are welded back into a mesh first: corners shared in the
//! user's mesh are bit-identical after the same transform, so welding on
//! their bits recovers its adjacency exactly (and never joins two vertices
//! that differ).

use super::Smoothies;
use crate::methods::{LightPoint, ShadowInputs, ShadowMethod};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

/// Triangle soup -> indexed mesh, welding bit-identical corners.
pub fn weld(tris: &[[Vec3; 3]]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(tris.len() * 2);
    let mut verts = Vec::with_capacity(tris.len() * 2);
    let faces = tris
        .iter()
        .map(|t| {
            t.map(|c| {
                let key = c.to_array().map(f32::to_bits);
                *index.entry(key).or_insert_with(|| {
                    verts.push(c.as_dvec3());
                    (verts.len() - 1) as u32
                })
            })
        })
        .collect();
    (verts, faces)
}

impl Smoothies {
    /// Points shaded against the occluders of `inputs`, given as an
    /// indexed mesh. The paper's shadow map holds the receivers too (its
    /// depth r behind a smoothie sizes the penumbra): where the receiver
    /// map shares the occluder grid (a light-view map) it is merged in;
    /// in the eye view every mesh is an occluder, so the front layer is
    /// already the whole scene.
    pub fn shade(
        &self,
        inputs: &ShadowInputs,
        verts: &[DVec3],
        faces: &[[u32; 3]],
        points: &[LightPoint],
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
        let buffer = self.buffer(og, inputs.light_size, map, verts, faces);
        self.visibility_points(og, map, &buffer, points)
    }

    fn welded(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let (verts, faces) = weld(inputs.occluder_triangles.unwrap_or(&[]));
        self.shade(inputs, &verts, &faces, points)
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_recovers_shared_corners_only() {
        let a = Vec3::new(0.0, 0.0, 1.0);
        let b = Vec3::new(1.0, 0.0, 1.0);
        let c = Vec3::new(0.0, 1.0, 1.0);
        let d = Vec3::new(1.0, 1.0, 1.0);
        let near_d = Vec3::new(1.0, 1.0, 1.0 + 1e-6);
        let (v, f) = weld(&[[a, b, c], [b, d, c], [b, near_d, c]]);
        assert_eq!(v.len(), 5);
        assert_eq!(f, vec![[0, 1, 2], [1, 3, 2], [1, 4, 2]]);
    }
}
