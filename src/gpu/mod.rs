//! The wgpu backend (cargo feature `gpu`): the mesh pipeline with every
//! per-texel stage as a WGSL compute shader. Each `.wgsl` file sits beside
//! the Rust module that drives it and has a CPU twin that reads the same way:
//!
//! * `raster.wgsl` (`raster.rs`): triangles into depth layers; twin
//!   `crate::raster` (same fixed-point coverage, same f32 depth plane).
//! * `gather.wgsl` + `ssm.wgsl` (`gather.rs`): row statistics and the
//!   published soft shadow map; twin `crate::methods::{gather, ssm}`.
//! * `gather.wgsl` + `bitmask.wgsl` (`gather.rs`): the bitmask method; twin
//!   `crate::methods::bitmask`.
//! * `exact.wgsl` (`exact.rs`): ray casting through the CPU-built BVH; twin
//!   `crate::methods::exact`.
//! * `eye_hits.wgsl` (`eye.rs`): the eye view's first hits, closest hit
//!   through the camera BVH; twin `Bvh::nearest` (`eye::gbuffer`).
//! * `eye_rays.wgsl` (`eye.rs`): the eye view's `exact`, shadow rays from
//!   the visible points; twin `crate::eye::rays`.
//! * `gather.wgsl`'s points mode (`gather.rs`, `gather_points.rs`): the eye
//!   view's map methods at arbitrary points; twin `methods::gather`'s
//!   `visibility_points`.
//! * `smoothies.wgsl` (`smoothies.rs`): Smoothies' buffer (the smoothies
//!   built on the CPU, binned to tiles, rasterized per texel with min
//!   blending) and lookup, light and eye view; twins
//!   `crate::methods::smoothies::{buffer, lookup}`.
//! * `shadow_mapping.wgsl` (`shadow_mapping.rs`): ShadowMapping's depth
//!   map, lookups and eye-space blur; twin `methods::shadow_mapping`'s
//!   `raster::scan`, `lookup::Lookup` and `blur::blur`.
//! * `pcss.wgsl` (`pcss.rs`): PCSS's blocker search, penumbra estimate
//!   and box PCF per output texel (light view) or per point (the eye view's
//!   points mode); twin `crate::methods::pcss` (with `methods::pcf`'s box).
//! * `u64.wgsl`: 64-bit integer helpers, placed before `raster.wgsl`,
//!   `shadow_mapping.wgsl` and `exact.wgsl` (and the eye modules, which append to `exact.wgsl`).
//!
//! Each method's module implements one interface, `GpuKernel`
//! (`method_kernel.rs`: its options' check, its light view's shading
//! stage, its eye view's map shading), and `kernel` below is the one place
//! that picks a method's: the stages run any method through it. A new GPU
//! method is its own module (and `.wgsl`), a `mod` line and an arm of
//! `kernel`.
//!
//! What the orchestrators (`crate::pipeline`) run: `light_view::GpuLightView`
//! (the light view's stages: the mesh maps and their shading in one
//! submission, `from_meshes.rs`; the user's depth maps shaded,
//! `from_depth.rs`) and `eye::GpuEye` (the eye view's stages, `eye.rs`);
//! this module never runs a sequence of its own. (They are not re-exported
//! here: they call `kernel`, and the files import one another one way.)
//! Device, queue and pipelines are made once per process (`context.rs`).

mod context;
#[cfg(test)]
mod device_tests;
mod dispatch;
mod exact;
pub(crate) mod eye;
mod from_depth;
mod from_meshes;
mod front_layer;
mod gather;
mod gather_points;
mod irradiance_weight;
mod light;
pub(crate) mod light_view;
mod method_kernel;
mod pcss;
mod point_rays;
mod raster;
mod readback;
mod refusals;
#[cfg(test)]
mod shader_tests;
mod shading;
mod shadow_mapping;
mod smoothies;
mod sphere_rays;
mod timing;

pub use context::{GpuInfo, ENV_SWITCH};

use crate::error::Result;
use crate::methods::Method;
use method_kernel::GpuKernel;

/// The GPU kernel of `method`: the only place in the backend that tells
/// the methods apart.
fn kernel(method: Method) -> &'static dyn GpuKernel {
    match method {
        Method::Ssm(_) | Method::Bitmask(_) => &gather_points::GatherKernel,
        Method::Exact(_) => &exact::ExactKernel,
        Method::Smoothies(_) => &smoothies::SmoothiesKernel,
        Method::Pcss(_) => &pcss::PcssKernel,
        // Its eye view is a stage of its own (`EyeStages::shadow_mapping`).
        Method::ShadowMapping(_) => &method_kernel::NoKernel,
    }
}

/// The adapter the GPU backend uses, opening it if needed;
/// `Error::GpuUnavailable` when there is none.
pub fn info() -> Result<GpuInfo> {
    context::gpu().map(|g| g.info.clone())
}

/// Whether `backend="gpu"` can run here (an adapter opens, software or not).
pub fn available() -> bool {
    context::gpu().is_ok()
}
