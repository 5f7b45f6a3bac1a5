//! The one interface every method's GPU module implements (`GpuKernel`),
//! and the shading stage its light view records (`Stage`). The orchestration
//! files (`from_meshes.rs`, `from_depth.rs`, `eye.rs`) run any method through
//! them, and `super::kernel` alone picks a method's kernel: a new GPU method
//! is its own module, implementing `GpuKernel`, and one line there.

use super::context::Gpu;
use super::gather::LayerCorners;
use super::readback::{submit_and_read, ReadBack};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::maps::LightTriangles;
use crate::eye::{Bias, Framed, MapShading};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};
use glam::DVec3;

/// A method's shading recorded after the maps it reads (the light view's,
/// and the eye view's front layer: `front_layer.rs`); it leaves one
/// visibility per receiver.
pub(super) trait Stage {
    /// Records the stage's passes, reading the maps in `maps` at the
    /// offsets the stage was made with.
    fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) -> Result<()>;

    /// What comes back, each buffer with its bytes: the visibility first,
    /// then the status words `check` reads, if any.
    fn outputs(&self) -> Vec<(&wgpu::Buffer, u64)>;

    /// Refuses a run whose status words (`outputs` after the visibility,
    /// read back) say the device stopped early.
    fn check(&self, _status: &[Vec<u8>]) -> Result<()> {
        Ok(())
    }
}

/// `stage` alone, recorded on the maps in `maps` (already on the device)
/// and its outputs read back: a shading whose maps were made by an earlier
/// submission or uploaded by the caller.
pub(super) fn run_stage(
    g: &Gpu,
    stage: &dyn Stage,
    maps: &wgpu::Buffer,
    label: &str,
    sw: &mut Stopwatch,
) -> Result<ReadBack> {
    let timer = StageTimer::new(g, 2);
    let mut enc = g
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    stage.record(g, &mut enc, &timer, maps)?;
    submit_and_read(g, enc, &timer, &stage.outputs(), sw)
}

/// What the light view's shading reads, from meshes or from the user's
/// depth maps: the maps lie in one buffer, the receiver map at 0, then the
/// occluder layers.
#[derive(Clone, Copy)]
pub(super) struct LightViewInputs<'a> {
    /// The receiver map's grid (the output's).
    pub grid: &'a MapGrid,
    pub occluder_grid: &'a MapGrid,
    pub light_shape: LightShape,
    /// Occluder layers in the maps (none for a method that traces).
    pub layers: u32,
    /// A bound on the occluders' 1/depth.
    pub w_max: f64,
    /// The occluders (kernel light space) and their faces; None from
    /// depth maps, which have no triangles.
    pub occluders: Option<(&'a [DVec3], &'a [[u32; 3]])>,
    /// The occluder layers' corners, made from the maps read back, for a
    /// kernel that waits for them.
    pub corners: Option<&'a LayerCorners>,
}

/// The device's part of a light-view stage: it makes the buffers when the
/// orchestrator runs it inside the error scopes (so a failed allocation is
/// an error, not a panic).
pub(super) type MakeStage<'a> = Box<dyn FnOnce() -> Result<Box<dyn Stage>> + 'a>;

/// What the eye view's map shading reads (`maps::shade`'s arguments).
pub(super) struct EyeInputs<'a> {
    pub f: &'a Framed,
    pub tris: &'a LightTriangles<'a>,
    pub grid: MapGrid,
    /// The occluder layers the config asks for.
    pub passes: u32,
    pub bias: &'a Bias,
}

/// A method on the GPU, both views. Each takes the `Method` it was picked
/// for (`super::kernel`), for its options.
pub(super) trait GpuKernel: Sync {
    /// Refuses, before any GPU work, options the kernel cannot run (by
    /// default none).
    fn check(&self, _method: Method) -> Result<()> {
        Ok(())
    }

    /// The light view's shading of `inputs`: the CPU's part now (in the
    /// orchestrator's "setup" stage), the device's in the `MakeStage`;
    /// None where the stage waits for `inputs.corners` (bitmask with
    /// closed gaps): the orchestrator reads the maps back, makes them and
    /// asks again.
    fn light_view<'a>(
        &self,
        g: &'a Gpu,
        method: Method,
        inputs: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>>;

    /// The eye view's map shading (`maps::shade` on the device): the
    /// visibility per visible point (weighted too where the method weighs
    /// its samples), the maps in the user's depth, and the device's stage
    /// times.
    fn eye(
        &self,
        g: &Gpu,
        method: Method,
        inputs: &EyeInputs,
        sw: &mut Stopwatch,
    ) -> Result<(MapShading, Timings)>;
}

/// The kernel of a method the GPU has none for (ShadowMapping, whose eye
/// view runs its own stage, `shadow_mapping.rs`): refused.
pub(super) struct NoKernel;

fn cpu_only(method: Method) -> Error {
    Error::invalid(
        "backend",
        format!(
            "{:?} runs on the CPU only in this version; use backend=\"cpu\"",
            method.name()
        ),
    )
}

impl GpuKernel for NoKernel {
    fn check(&self, method: Method) -> Result<()> {
        Err(cpu_only(method))
    }

    fn light_view<'a>(
        &self,
        _g: &'a Gpu,
        method: Method,
        _inputs: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>> {
        Err(cpu_only(method))
    }

    fn eye(
        &self,
        _g: &Gpu,
        method: Method,
        _inputs: &EyeInputs,
        _sw: &mut Stopwatch,
    ) -> Result<(MapShading, Timings)> {
        Err(cpu_only(method))
    }
}

/// A kernel handed a method it does not run (`super::kernel` picked it
/// wrongly).
pub(super) fn mismatch(method: Method) -> Error {
    Error::gpu(format!(
        "{:?} reached another method's GPU kernel (a bug: please report it)",
        method.name()
    ))
}

/// A kernel that waits for the corners, asked again with them (a bug).
pub(super) fn still_waits() -> Error {
    Error::gpu("a GPU kernel still waits for the corners it was given (a bug: please report it)")
}

/// The error of a kernel whose light view reads the occluders' triangles,
/// handed depth maps (`from_depth` refuses them before).
pub(super) fn needs_triangles(method: Method) -> Error {
    Error::invalid(
        "method",
        format!(
            "{:?} reads the occluder triangles, which depth maps do not have; use \
             soft_shadow_map with meshes",
            method.name()
        ),
    )
}
