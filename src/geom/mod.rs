//! Geometry: the light, its shape and its map grid, the camera, meshes, the depth unit the kernels
//! compute in, and the fitted extent of a light-view map.

pub mod body;
pub mod camera;
pub(crate) mod clip;
pub mod extent;
pub mod light;
pub mod light_shape;
pub mod light_space;
pub mod mesh;
pub mod plane_gradient;
pub mod shadow_projection;
pub mod sphere_light;
pub mod sun;
pub mod units;
