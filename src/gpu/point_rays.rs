//! The eye view's ray casting on the GPU, shared by `exact` under planar
//! lights (`eye.rs`, `eye_rays.wgsl`) and under a sphere
//! (`sphere_rays.rs`, `sphere_rays.wgsl`): both modules append to
//! exact.wgsl, keep one start per visible point at binding 8 and its
//! weights at 9, and are driven alike, a chunk of samples per dispatch
//! (lavapipe stops an invocation after 65535 loop iterations), then a
//! resolve.

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, storage, uniform, upload};
use super::exact::{budget_error, ExactParams, BUDGET, SAMPLES_PER_CHUNK};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::timing::StageTimer;
use crate::error::Result;
use crate::methods::exact::{Bvh, RAY_EPS};
use crate::timing::{Stopwatch, Timings};

/// Invocations per workgroup of both modules' entry points.
const GROUP: u32 = 64;

/// Per point: the visibility, and the weighted visibility.
pub(super) type Visibilities = (Vec<f32>, Vec<f32>);

/// A ray-casting module of the eye view appended to exact.wgsl (eye_rays.wgsl,
/// sphere_rays.wgsl): its cast and resolve entry points, and the buffers it
/// binds beside the BVH, the counts and the weights, made on the device:
/// the points' starts (binding 8) and its own, from binding 10 on (the cast
/// pass only).
pub(super) struct PointRays<B> {
    pub label: &'static str,
    /// The cast and resolve pipelines.
    pub pipelines: RayPipelines,
    pub buffers: B,
}

/// A module's cast and resolve pipelines, built once on the device.
pub(super) type RayPipelines = fn(
    &wgpu::Device,
) -> (
    &'static wgpu::ComputePipeline,
    &'static wgpu::ComputePipeline,
);

/// Casts `params`' strata (its light's na x nb) from each of its `rec_w`
/// points through `bvh`, a chunk of SAMPLES_PER_CHUNK samples per dispatch
/// (lavapipe's loop budget), each point's clear rays counted into `seen`
/// and their weights and every ray's summed into the weights (binding 9),
/// then the resolve into the visibility and the weighted visibility; and
/// the device's stage times. Segments t in (0, 1 - RAY_EPS) of each ray.
pub(super) fn cast_point_rays<B>(
    g: &Gpu,
    bvh: &Bvh,
    mut params: ExactParams,
    rays: PointRays<B>,
    sw: &mut Stopwatch,
) -> Result<(Visibilities, Timings)>
where
    B: FnOnce(&wgpu::Device) -> (wgpu::Buffer, Vec<wgpu::Buffer>),
{
    let n = params.rec_w as usize;
    params.rec_h = 1;
    params.budget = BUDGET;
    params.has_tris = u32::from(!bvh.is_empty());
    params.t0 = 0.0;
    params.t1 = 1.0 - RAY_EPS;
    let (na, nb) = params.strata();
    let bytes = n as u64 * 4;
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let (cast, resolve) = (rays.pipelines)(device);
        let nodes = upload(device, "bvh nodes", &bvh.node_words());
        let tri_buf = upload(device, "bvh triangles", &bvh.triangle_floats());
        let (start_buf, own) = (rays.buffers)(device);
        let seen = storage(device, "seen samples", bytes, wgpu::BufferUsages::COPY_DST);
        let status = storage(
            device,
            "status",
            4,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let vis = storage(
            device,
            "visibility",
            2 * bytes,
            wgpu::BufferUsages::COPY_SRC,
        );
        let weights = storage(
            device,
            "sample weights",
            2 * bytes,
            wgpu::BufferUsages::COPY_DST,
        );
        sw.lap("upload");
        let timer = StageTimer::new(g, 1);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some(rays.label),
        });
        enc.clear_buffer(&seen, 0, None);
        enc.clear_buffer(&weights, 0, None);
        enc.clear_buffer(&status, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
            let groups = groups_1d(n as u32, GROUP);
            pass.set_pipeline(cast);
            for chunk_start in (0..na * nb).step_by(SAMPLES_PER_CHUNK as usize) {
                let u = uniform(
                    device,
                    "exact params",
                    &ExactParams {
                        chunk_start,
                        chunk_len: SAMPLES_PER_CHUNK.min(na * nb - chunk_start),
                        ..params
                    },
                );
                let mut buffers = vec![
                    None,
                    Some(&nodes),
                    Some(&tri_buf),
                    Some(&u),
                    None,
                    None,
                    Some(&seen),
                    Some(&status),
                    Some(&start_buf),
                    Some(&weights),
                ];
                buffers.extend(own.iter().map(Some));
                let bg = bind(device, cast, &buffers);
                pass.set_bind_group(0, &bg, &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
            let u = uniform(device, "exact params", &params);
            let bg = bind(
                device,
                resolve,
                &[
                    None,
                    None,
                    None,
                    Some(&u),
                    None,
                    Some(&vis),
                    Some(&seen),
                    None,
                    Some(&start_buf),
                    Some(&weights),
                ],
            );
            pass.set_pipeline(resolve);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        submit_and_read(g, enc, &timer, &[(&vis, 2 * bytes), (&status, 4)], sw)
    })?;
    if words(&out.buffers[1])[0] != 0 {
        return Err(budget_error());
    }
    let mut v = visibility(&out.buffers[0])?;
    let weighted = v.split_off(n);
    Ok(((v, weighted), out.device_timings))
}
