//! The light view's stages as one interface, implemented by the CPU
//! (`CpuLightView`, `cpu.rs`) and by the GPU
//! (`crate::gpu::light_view::GpuLightView`): the orchestrators
//! (`crate::pipeline::from_meshes`, `from_depth`) run one sequence on
//! either, from the same framing (`crate::frame`), and build one result.
//!
//! The GPU fuses rasterization and shading into one submission (the maps
//! never come back between them), so a stage here is "the maps and their
//! visibility" of a framed scene, or "the visibility" of depth maps in the
//! kernels' unit; each backend times its own steps inside it.

mod cpu;
pub mod estimate;
mod stages;

pub use cpu::CpuLightView;
pub use stages::{LightMaps, LightViewStages};
