//! The eye view's stages: a scene seen through a camera, every mesh casting
//! and receiving shadows (its own included), lit by a rectangle or the sun.
//! The order they run in is `crate::pipeline::eye_view`'s, one sequence for
//! both backends; each stage here has a GPU twin in `crate::gpu`
//! (`stages.rs` is the interface both implement).
//!
//! Stages (timed): `first_hits` (gbuffer.rs: what each pixel sees),
//! `transform` (framing.rs: the scene to the kernels' light space), then
//! per method what it reads: `exact` traces shadow rays from each surface
//! point (rays.rs); the map methods rasterize occluder layers focused on
//! the visible points (focus.rs, casters.rs) and shade each pixel at its own
//! point and depth with the biases of maps.rs (`extent`,
//! `raster_occluders`, `shadow`); ShadowMapping has its own
//! (shadow_mapping.rs). Visibility is 1 where a pixel sees no surface. A
//! rectangle lights its n side only: `rays::plane_side` has no side for a
//! point at or behind its plane, which exact (no ray start) and the map
//! methods (the tangent-plane bound) both turn into 0.
//!
//! Every backend's visibility is then shaded on the CPU (shading.rs:
//! Lambertian direct lighting, unshadowed and times the visibility), so
//! both backends shade a visibility alike.

pub mod albedo;
pub mod budget;
pub mod call;
mod casters;
pub mod estimate;
pub mod focus;
pub mod framing;
mod gather_budget;
pub mod gbuffer;
pub mod maps;
pub mod prepared;
pub mod rays;
pub mod shading;
pub mod shadow_mapping;
pub mod sphere_rays;
pub mod stages;
pub mod tangent_plane;

pub use call::{EyeCall, EyeImage, MAX_LIGHTS};
pub use framing::Framed;
pub use gbuffer::GBuffer;
pub use maps::{Bias, EyeMaps, MapShading, DEFAULT_BIAS, MAX_BIAS};
pub use shading::{Lighting, Shaded};
pub use stages::{CpuEye, EyeStages};
