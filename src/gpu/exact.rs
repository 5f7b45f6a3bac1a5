//! The `exact` method on the GPU: the BVH is built on the CPU (as
//! `methods/exact.rs` builds it) and uploaded with the triangles; `exact.wgsl`
//! casts the stratified samples of each receiver texel through it, a chunk of
//! samples per dispatch, then resolves the counts into visibility.
//!
//! `ExactKernel` (its `GpuKernel`) runs the light view; in the eye view
//! `exact` is no map method: `GpuEye::trace` casts its rays (`eye.rs`,
//! `eye_rays.wgsl`, which appends to this module's WGSL).

use super::context::Gpu;
use super::dispatch::{bind, module, pipeline, storage, uniform, upload};
use super::light::GpuLightSamples;
use super::method_kernel::{
    mismatch, needs_triangles, EyeInputs, GpuKernel, LightViewInputs, MakeStage, Stage,
};
use super::readback::words;
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::MapShading;
use crate::frame::light_space_triangles;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::exact::{Bvh, RAY_EPS};
use crate::methods::{Exact, Method};
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use std::sync::OnceLock;

/// The module: the 64-bit helpers it calls (u64.wgsl), then exact.wgsl.
/// The ray caster's module: the 64-bit helpers, the light's sampling
/// (`light.rs`), then exact.wgsl.
pub const SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl")
);

/// Loop iterations (BVH nodes visited and triangles tested) one invocation
/// may run per dispatch; lavapipe stops an invocation after 65535.
pub(super) const BUDGET: u32 = 50_000;
/// Samples per dispatch: BUDGET / SAMPLES_PER_CHUNK iterations a ray.
pub(super) const SAMPLES_PER_CHUNK: u32 = 4;

/// `ExactParams` of exact.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct ExactParams {
    pub rec_w: u32,
    pub rec_h: u32,
    pub chunk_start: u32,
    pub chunk_len: u32,
    /// The light's sample pattern (`set_light`).
    pub light: GpuLightSamples,
    pub budget: u32,
    pub has_tris: u32,
    pub t0: f32,
    pub t1: f32,
    pub ax_rec_x: u32,
    pub ax_rec_y: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

impl ExactParams {
    /// The ray casters' sample pattern: `samples` strata over `light`, the
    /// one place a light shape reaches these uniforms (exact.wgsl and
    /// eye_rays.wgsl read them through light_shape.wgsl).
    pub(super) fn set_light(&mut self, light: LightShape, samples: u32) {
        self.light = GpuLightSamples::new(light.samples(samples));
    }

    /// The rays a receiver casts: na x nb.
    pub(super) fn strata(&self) -> (u32, u32) {
        (self.light.na, self.light.nb)
    }
}

struct ExactPipelines {
    cast: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static ExactPipelines {
    static P: OnceLock<ExactPipelines> = OnceLock::new();
    P.get_or_init(|| {
        let m = module(device, "exact.wgsl", SOURCE);
        ExactPipelines {
            cast: pipeline(device, &m, "exact"),
            resolve: pipeline(device, &m, "exact_resolve"),
        }
    })
}

/// A ray visited more nodes than `BUDGET` (the status word the shaders set).
pub(super) fn budget_error() -> Error {
    Error::gpu(
        "a ray visited more BVH nodes than one invocation may (lavapipe stops an \
         invocation after 65535 loop iterations); use backend=\"cpu\" for this scene",
    )
}

/// The buffers and parameters of the ray-casting stage.
pub struct ExactShading {
    params: ExactParams,
    samples: u32,
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    axes: wgpu::Buffer,
    seen: wgpu::Buffer,
    status: wgpu::Buffer,
    vis: wgpu::Buffer,
    vis_bytes: u64,
}

impl ExactShading {
    /// Builds the BVH over the light-space triangles and uploads it.
    pub fn new(
        g: &Gpu,
        grid: &MapGrid,
        tris: Vec<[Vec3; 3]>,
        samples: u32,
        light_shape: LightShape,
    ) -> ExactShading {
        let device = &g.device;
        let has_tris = !tris.is_empty();
        let bvh = Bvh::build(tris);
        let axes: Vec<f32> = (0..grid.width)
            .map(|i| grid.x_of(i) as f32)
            .chain((0..grid.height).map(|j| grid.y_of(j) as f32))
            .collect();
        let vis_bytes = grid.len() as u64 * 4;
        let mut params = ExactParams {
            rec_w: grid.width as u32,
            rec_h: grid.height as u32,
            budget: BUDGET,
            has_tris: has_tris as u32,
            t0: RAY_EPS,
            t1: 1.0 - RAY_EPS,
            ax_rec_x: 0,
            ax_rec_y: grid.width as u32,
            ..Default::default()
        };
        params.set_light(light_shape, samples);
        let (na, nb) = params.strata();
        ExactShading {
            params,
            samples: na * nb,
            nodes: upload(device, "bvh nodes", &bvh.node_words()),
            tris: upload(device, "bvh triangles", &bvh.triangle_floats()),
            axes: upload(device, "axes", &axes),
            seen: storage(
                device,
                "seen samples",
                vis_bytes,
                wgpu::BufferUsages::COPY_DST,
            ),
            status: storage(
                device,
                "status",
                4,
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            ),
            vis: storage(
                device,
                "visibility",
                vis_bytes,
                wgpu::BufferUsages::COPY_SRC,
            ),
            vis_bytes,
        }
    }
}

impl Stage for ExactShading {
    /// Records the pass "shadow": one dispatch per chunk of samples, then
    /// the resolve.
    fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) -> Result<()> {
        let device = &g.device;
        let p = pipelines(device);
        enc.clear_buffer(&self.seen, 0, None);
        enc.clear_buffer(&self.status, 0, None);
        let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
        let groups = (self.params.rec_w.div_ceil(8), self.params.rec_h.div_ceil(8));
        pass.set_pipeline(&p.cast);
        for chunk_start in (0..self.samples).step_by(SAMPLES_PER_CHUNK as usize) {
            let u = uniform(
                device,
                "exact params",
                &ExactParams {
                    chunk_start,
                    chunk_len: SAMPLES_PER_CHUNK.min(self.samples - chunk_start),
                    ..self.params
                },
            );
            let refs = [
                Some(maps),
                Some(&self.nodes),
                Some(&self.tris),
                Some(&u),
                Some(&self.axes),
                None,
                Some(&self.seen),
                Some(&self.status),
            ];
            pass.set_bind_group(0, &bind(device, &p.cast, &refs), &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        let u = uniform(device, "exact params", &self.params);
        let bg = bind(
            device,
            &p.resolve,
            &[
                Some(maps),
                None,
                None,
                Some(&u),
                Some(&self.axes),
                Some(&self.vis),
                Some(&self.seen),
            ],
        );
        pass.set_pipeline(&p.resolve);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
        Ok(())
    }

    fn outputs(&self) -> Vec<(&wgpu::Buffer, u64)> {
        vec![(&self.vis, self.vis_bytes), (&self.status, 4)]
    }

    fn check(&self, status: &[Vec<u8>]) -> Result<()> {
        if words(&status[0])[0] != 0 {
            return Err(budget_error());
        }
        Ok(())
    }
}

/// `exact`'s kernel: rays through the occluders' BVH at every receiver
/// texel (light view only).
pub(super) struct ExactKernel;

impl GpuKernel for ExactKernel {
    fn light_view<'a>(
        &self,
        g: &'a Gpu,
        method: Method,
        i: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>> {
        let Method::Exact(Exact { samples, .. }) = method else {
            return Err(mismatch(method));
        };
        let (verts, faces) = i.occluders.ok_or_else(|| needs_triangles(method))?;
        Ok(Some(Box::new(move || {
            let t = light_space_triangles(verts, faces);
            let sh = ExactShading::new(g, i.grid, t, samples, i.light_shape);
            // A cancelled build is cut short (`crate::cancel`): not for the device.
            crate::cancel::current().check()?;
            Ok(Box::new(sh) as Box<dyn Stage>)
        })))
    }

    // The eye view's `exact` traces (`EyeStages::trace`), never here.
    fn eye(
        &self,
        _g: &Gpu,
        _method: Method,
        _inputs: &EyeInputs,
        _sw: &mut Stopwatch,
    ) -> Result<(MapShading, Timings)> {
        Err(Error::gpu(
            "exact has no map stage: the eye view traces its rays (GpuEye::trace) \
             (a bug: please report it)",
        ))
    }
}
