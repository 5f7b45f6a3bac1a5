//! The eye view on the GPU (`render(..., backend="gpu")`): `GpuEye`, the
//! twin of `eye::CpuEye` (src/eye/stages.rs) that `pipeline::eye_view`
//! runs, stage for stage, with the same answers.
//!
//! * First hits (`eye_hits.wgsl`): each pixel-centre ray o = 0 (eye-relative),
//!   d = `gbuffer::pixel_ray` (f32, uploaded) is cast through the camera BVH
//!   (`gbuffer::camera_bvh`, built on the CPU) for its nearest triangle,
//!   t in (0, best), as `Bvh::nearest` does; the slot comes back, is mapped to
//!   the input triangle (`Bvh::order`) and the G-buffer is built on the CPU
//!   in f64 (`gbuffer::from_hits`, shared). The cast's CPU twin is the
//!   camera BVH's `nearest` (the device tests find the same triangle at
//!   every pixel on lavapipe); the CPU's own G-buffer rasterizes the same
//!   pixel centres (`gbuffer::rasterized_hits`), so the two backends'
//!   G-buffers may differ where a pixel centre grazes an edge.
//! * Framing (CPU, shared with the CPU path: `eye::framing`):
//!   the light space, the depth unit, the triangles in kernel light space,
//!   the focused grid and its resolution.
//! * `exact` (`eye_rays.wgsl`): per visible point, stratified shadow rays
//!   from the two spawn_ray_to origins of `rays::ray_starts` (made on the
//!   CPU in f64, shared), t in (0, 1 - RAY_EPS), the jitter exact.rs's hash
//!   of the point's pixel (its flat index in the image) and the sample, as
//!   `rays::visibility`.
//! * `exact` under a sphere (`sphere_rays.wgsl`, `sphere_rays.rs`): each
//!   pixel's rays over the cap it sees, the frames and origins made on the
//!   CPU in f64, as `eye::sphere_rays` traces them (without a probe).
//! * The map methods (`ssm`, `bitmask`, `pcss`, `smoothies`): the method's
//!   kernel (`super::kernel`, `GpuKernel::eye`: `gather_points.rs`,
//!   `pcss.rs`, `smoothies.rs`) rasterizes the occluder layers on the
//!   device and shades the biased points, as `maps::shade`.
//!   A hard light has no GPU map kernel and is refused (`exact` runs it,
//!   with one ray).
//!
//! Two submissions: the first hits (the CPU needs them to place everything
//! else), then the shading with one readback of the visibility (and maps);
//! three with bitmask's closed gaps (the layers, then the shading).

use super::context::{gpu, Gpu};
use super::dispatch::{bind, groups_1d, module, pipeline, storage, uniform, upload};
use super::exact::{budget_error, ExactParams};
use super::method_kernel::EyeInputs;
use super::point_rays::{cast_point_rays, PointRays, Visibilities};
use super::readback::{submit_and_read, with_error_scopes, words};
use super::refusals::{check_side, fits, point_light_on_gpu};
use super::timing::{merged, StageTimer};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::eye::framing::resolve_at_camera;
use crate::eye::gbuffer::{self, GBuffer, SceneTriangles};
use crate::eye::maps::LightTriangles;
use crate::eye::rays::{self, RayStart};
use crate::eye::{EyeCall, EyeStages, Framed, MapShading};
use crate::geom::camera::Camera;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::sphere_light::SphereLight;
use crate::methods::engine::Engine;
use crate::methods::exact::Bvh;
use crate::methods::shadow_mapping::config::ShadowMappingConfig;
use crate::methods::MethodConfig;
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use std::sync::OnceLock;

/// The first-hit module: the 64-bit helpers, the light's sampling (which
/// exact.wgsl's ray caster calls), exact.wgsl (BVH access, the watertight test),
/// then eye_hits.wgsl.
pub const HITS_SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl"),
    "\n",
    include_str!("eye_hits.wgsl")
);
/// The shadow-ray module: the light's sampling, exact.wgsl's traversal and
/// jitter, the receivers' weights, then eye_rays.wgsl.
pub const RAYS_SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl"),
    "\n",
    include_str!("irradiance_weight.wgsl"),
    "\n",
    include_str!("eye_rays.wgsl")
);

/// Loop iterations (nodes visited and triangles tested) a first-hit
/// invocation may run; lavapipe stops an invocation after 65535.
const HITS_BUDGET: u32 = 50_000;
/// Invocations per workgroup of the first hits and the shadow rays.
const GROUP: u32 = 64;

/// `HitsParams` of eye_hits.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct HitsParams {
    pub n: u32,
    pub budget: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// `RayStart` of eye_rays.wgsl: a point's two origins (kernel light space)
/// and the side test choosing between them; `valid` 0: visibility 0. (Every
/// point's rays go to one shared pattern: no per-point key.)
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct GpuRayStart {
    pub ax: f32,
    pub ay: f32,
    pub az: f32,
    pub valid: u32,
    pub bx: f32,
    pub by: f32,
    pub bz: f32,
    pub a0: f32,
    pub au: f32,
    pub av: f32,
    pub _pad0: u32,
    pub _pad1: u32,
}

struct EyePipelines {
    hits: wgpu::ComputePipeline,
    rays: wgpu::ComputePipeline,
    rays_resolve: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static EyePipelines {
    static P: OnceLock<EyePipelines> = OnceLock::new();
    P.get_or_init(|| {
        let h = module(device, "eye_hits.wgsl", HITS_SOURCE);
        let r = module(device, "eye_rays.wgsl", RAYS_SOURCE);
        EyePipelines {
            hits: pipeline(device, &h, "eye_hits"),
            rays: pipeline(device, &r, "eye_exact"),
            rays_resolve: pipeline(device, &r, "eye_exact_resolve"),
        }
    })
}

/// The eye view's stages on the GPU (`eye::EyeStages`): the first hits,
/// the shadow rays, the occluder layers and the gather on the device, the
/// framing shared with the CPU; the device's stage times are kept here
/// until the orchestrator asks for them.
#[derive(Default)]
pub struct GpuEye {
    device_timings: Timings,
}

impl EyeStages for GpuEye {
    const BACKEND: Backend = Backend::Gpu;

    // Refuses what the GPU cannot run before any GPU work: a config that
    // does not resolve there, a hard light for the map methods.
    fn check(&self, call: &EyeCall) -> Result<()> {
        let method = resolve_at_camera(call, Backend::Gpu)?.kernel();
        if !method.traces() && call.light.is_hard() {
            return Err(point_light_on_gpu("size"));
        }
        super::kernel(method).check(method)
    }

    fn first_hits(&mut self, camera: &Camera, scene: &SceneTriangles) -> Result<GBuffer> {
        let (hit, t) = first_hits(gpu()?, camera, scene)?;
        self.device_timings.extend(t);
        Ok(gbuffer::from_hits(camera, scene, &hit))
    }

    fn shadow_mapping(
        &mut self,
        call: &EyeCall,
        cfg: &ShadowMappingConfig,
        scene: &SceneTriangles,
        g: &GBuffer,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        let (v, _) = super::shadow_mapping::render_prepared(
            gpu()?,
            call,
            cfg,
            scene,
            g,
            false,
            sw,
            &mut self.device_timings,
        )?;
        Ok(v)
    }

    fn trace(
        &mut self,
        f: &Framed,
        bvh: &Bvh,
        _camera: &Camera,
        (samples, probe, engine): (u32, Option<u32>, Engine),
        sw: &mut Stopwatch,
    ) -> Result<(Vec<f32>, Option<Vec<f32>>)> {
        // `ExactConfig::resolve` refuses a probe and the masks on the GPU.
        if probe.is_some() {
            return Err(no_probe());
        }
        debug_assert_eq!(engine, Engine::Rays);
        let starts: Vec<GpuRayStart> = rays::ray_starts(&f.space, f.unit, &f.points, &f.normals)
            .iter()
            .map(GpuRayStart::new)
            .collect();
        let ((v, weighted), t) =
            exact_visibility(gpu()?, bvh, &starts, samples, f.light_shape, sw)?;
        self.device_timings.extend(t);
        Ok((v, Some(weighted)))
    }

    fn trace_sphere(
        &mut self,
        bvh: &Bvh,
        light: &SphereLight,
        g: &GBuffer,
        hits: &[usize],
        samples: u32,
        probe: Option<u32>,
        sw: &mut Stopwatch,
    ) -> Result<Vec<[f32; 2]>> {
        if probe.is_some() {
            return Err(no_probe());
        }
        let (v, t) =
            super::sphere_rays::sphere_visibility(gpu()?, bvh, light, g, hits, samples, sw)?;
        self.device_timings.extend(t);
        Ok(v)
    }

    fn shade_maps(
        &mut self,
        call: &EyeCall,
        f: &Framed,
        tris: &LightTriangles,
        grid: MapGrid,
        method: &MethodConfig,
        sw: &mut Stopwatch,
    ) -> Result<MapShading> {
        check_side("map_resolution", (grid.width, grid.height))?;
        let resolved = method.kernel();
        let inputs = EyeInputs {
            f,
            tris,
            grid,
            passes: method.passes(),
            bias: &call.bias,
        };
        let (shading, t) = super::kernel(resolved).eye(gpu()?, resolved, &inputs, sw)?;
        self.device_timings.extend(t);
        Ok(shading)
    }

    // Several submissions time some stages more than once: summed.
    fn timings(&mut self, host: Timings) -> Timings {
        let mut timings = host;
        timings.extend(std::mem::take(&mut self.device_timings));
        merged(timings)
    }
}

/// A probe asked of the GPU, which has none.
fn no_probe() -> Error {
    Error::invalid(
        "probe",
        "the GPU backend traces every sample at every pixel (it has no probe); use backend=\"cpu\"",
    )
}

/// The triangle (input index) each pixel's ray hits first, cast on the
/// device; and the device's time ("gpu_first_hits").
pub(crate) fn first_hits(
    g: &Gpu,
    camera: &Camera,
    scene: &SceneTriangles,
) -> Result<(Vec<Option<u32>>, Timings)> {
    let bvh = gbuffer::camera_bvh(camera, scene);
    // A cancelled build is cut short (`crate::cancel`): not for the device.
    crate::cancel::current().check()?;
    let n = camera.width * camera.height;
    fits(g, "resolution", n as u64 * 12)?;
    if n >= u32::MAX as usize {
        return Err(Error::too_large(
            "resolution",
            "too many pixels for the GPU",
        ));
    }
    let dirs: Vec<f32> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .flat_map_iter(|k| gbuffer::pixel_ray(camera, k).to_array())
        .collect();
    let mut sw = Stopwatch::new();
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let p = pipelines(device);
        let nodes = upload(device, "camera bvh nodes", &bvh.node_words());
        let tris = upload(device, "camera bvh triangles", &bvh.triangle_floats());
        let dirs = upload(device, "ray directions", &dirs);
        let hits = storage(
            device,
            "first hits",
            n as u64 * 4,
            wgpu::BufferUsages::COPY_SRC,
        );
        let status = storage(
            device,
            "status",
            4,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let u = uniform(
            device,
            "hits params",
            &HitsParams {
                n: n as u32,
                budget: HITS_BUDGET,
                ..Default::default()
            },
        );
        let timer = StageTimer::new(g, 1);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow eye first hits"),
        });
        enc.clear_buffer(&status, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("first_hits"));
            let bg = bind(
                device,
                &p.hits,
                &[
                    None,
                    Some(&nodes),
                    Some(&tris),
                    None,
                    None,
                    None,
                    None,
                    Some(&status),
                    Some(&u),
                    Some(&dirs),
                    Some(&hits),
                ],
            );
            pass.set_pipeline(&p.hits);
            pass.set_bind_group(0, &bg, &[]);
            let (x, y) = groups_1d(n as u32, GROUP);
            pass.dispatch_workgroups(x, y, 1);
        }
        submit_and_read(
            g,
            enc,
            &timer,
            &[(&hits, n as u64 * 4), (&status, 4)],
            &mut sw,
        )
    })?;
    if words(&out.buffers[1])[0] != 0 {
        return Err(budget_error());
    }
    let order = bvh.order();
    let hit = words(&out.buffers[0])
        .into_iter()
        .map(|s| (s != u32::MAX).then(|| order[s as usize]))
        .collect();
    // Without timestamps the submission's wall time is named for its stage.
    let timings = out
        .device_timings
        .into_iter()
        .map(|(name, t)| {
            (
                if name == "gpu" {
                    "gpu_first_hits"
                } else {
                    name
                },
                t,
            )
        })
        .collect();
    Ok((hit, timings))
}

impl GpuRayStart {
    /// `rays::RayStart` of a point as eye_rays.wgsl reads it; `None`: not
    /// valid.
    pub fn new(s: &Option<RayStart>) -> GpuRayStart {
        match s {
            None => GpuRayStart::default(),
            Some(s) => GpuRayStart {
                ax: s.above.x,
                ay: s.above.y,
                az: s.above.z,
                valid: 1,
                bx: s.below.x,
                by: s.below.y,
                bz: s.below.z,
                a0: s.side[0],
                au: s.side[1],
                av: s.side[2],
                _pad0: 0,
                _pad1: 0,
            },
        }
    }
}

/// `exact`'s visibility per ray start and its weighted visibility
/// (eye_rays.wgsl), through a BVH of `tris` (kernel light space) on the
/// device; and the device's stage times.
fn exact_visibility(
    g: &Gpu,
    bvh: &Bvh,
    starts: &[GpuRayStart],
    samples: u32,
    light_shape: LightShape,
    sw: &mut Stopwatch,
) -> Result<(Visibilities, Timings)> {
    let n = starts.len();
    if n == 0 {
        return Ok(((vec![], vec![]), vec![]));
    }
    fits(g, "resolution", n as u64 * size_of::<GpuRayStart>() as u64)?;
    let mut params = ExactParams {
        rec_w: n as u32,
        ..Default::default()
    };
    params.set_light(light_shape, samples);
    let rays = PointRays {
        label: "softshadow eye exact",
        pipelines: |d| {
            let p = pipelines(d);
            (&p.rays, &p.rays_resolve)
        },
        buffers: |d: &wgpu::Device| (upload(d, "ray starts", starts), vec![]),
    };
    cast_point_rays(g, bvh, params, rays, sw)
}
