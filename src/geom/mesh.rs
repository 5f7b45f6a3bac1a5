//! Triangle meshes handed to the core: validation and the move to light space.

use crate::error::{Error, Result};
use crate::geom::light_space::LightSpace;
use glam::DVec3;
use rayon::prelude::*;

/// A borrowed triangle mesh: world-space vertices and triangle indices.
#[derive(Debug, Clone, Copy)]
pub struct MeshRef<'a> {
    pub vertices: &'a [[f64; 3]],
    pub faces: &'a [[u32; 3]],
}

impl<'a> MeshRef<'a> {
    /// Refuses non-finite vertices and out-of-range indices. `arg` names the
    /// mesh set in errors ("occluders", "receivers").
    pub fn validate(&self, arg: &str) -> Result<()> {
        if let Some(k) = self
            .vertices
            .par_iter()
            .position_any(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(
                arg,
                format!("vertex {k} is not finite: {:?}", self.vertices[k]),
            ));
        }
        let nv = self.vertices.len();
        if let Some(k) = self
            .faces
            .par_iter()
            .position_any(|f| f.iter().any(|&i| i as usize >= nv))
        {
            return Err(Error::invalid(
                arg,
                format!(
                    "face {k} has vertex indices {:?} out of range for {nv} vertices",
                    self.faces[k]
                ),
            ));
        }
        Ok(())
    }

    /// Vertices in light space (X, Y, Z), computed in f64.
    pub fn to_light_space(&self, light: &LightSpace) -> Vec<DVec3> {
        self.vertices
            .par_iter()
            .map(|p| light.to_light(DVec3::from_array(*p)))
            .collect()
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }
}
