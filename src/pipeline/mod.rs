//! One orchestrator per view, each running its stages on the CPU (here)
//! or their GPU twins (`crate::gpu`), timed per stage:
//! `from_meshes` (the light view: meshes framed, light-view maps
//! rasterized, then shaded), `from_scene` (the light view of a scene
//! shadowing itself), `from_depth` (the user's depth maps shaded),
//! `points` (visibility at world points) and `eye_view` (a camera's image).
//! `crate::api` picks the backend.

pub mod eye_view;
mod from_depth;
mod from_meshes;
mod from_scene;
mod points;

pub use from_depth::{from_depth, from_depth_with, DepthMaps};
pub use from_meshes::{from_meshes, from_meshes_with};
pub use from_scene::from_scene;
pub use points::{receiver_points, sample_points, OccluderSource};
