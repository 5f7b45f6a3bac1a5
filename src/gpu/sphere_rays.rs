//! `exact` under a sphere light on the GPU (`sphere_rays.wgsl`), the twin
//! of `eye::sphere_rays::sphere_visibility` without its probe: the CPU sets
//! every pixel up in f64 (its two ray origins and its cap frame, relative
//! to the sphere's centre, `GpuSphereStart::new`) and the shared pattern's
//! cap samples (`shared_cap_samples`); the device casts a chunk of samples
//! per dispatch through the BVH of every triangle relative to the centre
//! (`sphere_bvh`, exact.wgsl's traversal) and resolves the counts and
//! weights into the visibility and the weighted visibility.

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, module, pipeline, storage, uniform, upload};
use super::exact::{budget_error, ExactParams, BUDGET, SAMPLES_PER_CHUNK};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::refusals::fits;
use super::timing::StageTimer;
use crate::error::Result;
use crate::eye::gbuffer::GBuffer;
use crate::eye::sphere_rays::{ray_origins, shared_cap_samples};
use crate::geom::light_shape::sphere::CapFrame;
use crate::geom::light_shape::LightShape;
use crate::geom::sphere_light::SphereLight;
use crate::methods::exact::{Bvh, RAY_EPS};
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// The module: the 64-bit helpers, the light's sampling and exact.wgsl
/// (whose traversal and bindings it reads), then sphere_rays.wgsl.
pub const SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl"),
    "\n",
    include_str!("sphere_rays.wgsl")
);

/// Invocations per workgroup (sphere_rays.wgsl's SPHERE_GROUP).
const GROUP: u32 = 64;

/// `SphereStart` of sphere_rays.wgsl: a pixel's two ray origins, normal and
/// cap frame, relative to the sphere's centre; `valid` 0 inside the sphere.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct GpuSphereStart {
    pub ax: f32,
    pub ay: f32,
    pub az: f32,
    pub valid: u32,
    pub bx: f32,
    pub by: f32,
    pub bz: f32,
    pub omc: f32,
    pub nx: f32,
    pub ny: f32,
    pub nz: f32,
    pub wx: f32,
    pub wy: f32,
    pub wz: f32,
    pub e1x: f32,
    pub e1y: f32,
    pub e1z: f32,
    pub e2x: f32,
    pub e2y: f32,
    pub e2z: f32,
}

/// `SphereParams` of sphere_rays.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct SphereParams {
    pub radius: f32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

impl GpuSphereStart {
    /// The pixel at `p` with normal `n` under `light`, as `trace_packet`
    /// sets its lane up; not valid inside the sphere.
    pub fn new(light: &SphereLight, p: DVec3, n: DVec3) -> GpuSphereStart {
        let c = light.center;
        let Some(frame) = CapFrame::new(c, light.radius, p).filter(|_| light.is_outside(p)) else {
            return GpuSphereStart::default();
        };
        let ([w, e1, e2], omc) = frame.parts();
        let [a, b] = ray_origins(p, n).map(|o| (o - c).as_vec3());
        let (n, w, e1, e2) = (n.as_vec3(), w.as_vec3(), e1.as_vec3(), e2.as_vec3());
        GpuSphereStart {
            ax: a.x,
            ay: a.y,
            az: a.z,
            valid: 1,
            bx: b.x,
            by: b.y,
            bz: b.z,
            omc: omc as f32,
            nx: n.x,
            ny: n.y,
            nz: n.z,
            wx: w.x,
            wy: w.y,
            wz: w.z,
            e1x: e1.x,
            e1y: e1.y,
            e1z: e1.z,
            e2x: e2.x,
            e2y: e2.y,
            e2z: e2.z,
        }
    }
}

struct Pipelines {
    cast: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static Pipelines {
    static P: OnceLock<Pipelines> = OnceLock::new();
    P.get_or_init(|| {
        let m = module(device, "sphere_rays.wgsl", SOURCE);
        Pipelines {
            cast: pipeline(device, &m, "eye_sphere"),
            resolve: pipeline(device, &m, "eye_sphere_resolve"),
        }
    })
}

/// Each pixel of `hits` (flat indices into `g`): its visibility and
/// weighted visibility under `light` from `samples` rays over its cap
/// through `bvh` (`sphere_bvh`), on the device; and the device's times.
pub(super) fn sphere_visibility(
    g: &Gpu,
    bvh: &Bvh,
    light: &SphereLight,
    gb: &GBuffer,
    hits: &[usize],
    samples: u32,
    sw: &mut Stopwatch,
) -> Result<(Vec<[f32; 2]>, Timings)> {
    let n = hits.len();
    if n == 0 {
        return Ok((vec![], vec![]));
    }
    fits(
        g,
        "resolution",
        n as u64 * size_of::<GpuSphereStart>() as u64,
    )?;
    let starts: Vec<GpuSphereStart> = hits
        .par_iter()
        .with_min_len(1024)
        .map(|&k| {
            let p = DVec3::from_array(gb.position[k]);
            let nrm = glam::Vec3::from_array(gb.normal[k]).as_dvec3();
            GpuSphereStart::new(light, p, nrm)
        })
        .collect();
    let ((na, nb), table) = shared_cap_samples(samples);
    let table: Vec<f32> = table.iter().flat_map(|s| s.map(|x| x as f32)).collect();
    let mut params = ExactParams {
        rec_w: n as u32,
        rec_h: 1,
        budget: BUDGET,
        has_tris: u32::from(!bvh.is_empty()),
        // trace_packet's segments: t in (0, 1 - RAY_EPS).
        t0: 0.0,
        t1: 1.0 - RAY_EPS,
        ..Default::default()
    };
    // The strata of the shared pattern (the unit square's, as the CPU's).
    params.set_light(LightShape::rect([1.0, 1.0]), samples);
    debug_assert_eq!(params.strata(), (na, nb));
    let sphere = SphereParams {
        radius: light.radius as f32,
        ..Default::default()
    };
    let bytes = n as u64 * 4;
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let p = pipelines(device);
        let nodes = upload(device, "sphere bvh nodes", &bvh.node_words());
        let tris = upload(device, "sphere bvh triangles", &bvh.triangle_floats());
        let caps = upload(device, "sphere starts", &starts);
        let table = upload(device, "cap samples", &table);
        let su = uniform(device, "sphere params", &sphere);
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
            "cap weights",
            2 * bytes,
            wgpu::BufferUsages::COPY_DST,
        );
        sw.lap("upload");
        let timer = StageTimer::new(g, 1);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow eye sphere"),
        });
        enc.clear_buffer(&seen, 0, None);
        enc.clear_buffer(&weights, 0, None);
        enc.clear_buffer(&status, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
            let groups = groups_1d(n as u32, GROUP);
            pass.set_pipeline(&p.cast);
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
                let bg = bind(
                    device,
                    &p.cast,
                    &[
                        None,
                        Some(&nodes),
                        Some(&tris),
                        Some(&u),
                        None,
                        None,
                        Some(&seen),
                        Some(&status),
                        Some(&caps),
                        Some(&weights),
                        Some(&table),
                        Some(&su),
                    ],
                );
                pass.set_bind_group(0, &bg, &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
            let u = uniform(device, "exact params", &params);
            let bg = bind(
                device,
                &p.resolve,
                &[
                    None,
                    None,
                    None,
                    Some(&u),
                    None,
                    Some(&vis),
                    Some(&seen),
                    None,
                    Some(&caps),
                    Some(&weights),
                    None,
                    None,
                ],
            );
            pass.set_pipeline(&p.resolve);
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
    Ok((
        v.into_iter().zip(weighted).map(|(v, w)| [v, w]).collect(),
        out.device_timings,
    ))
}
