//! `exact` under a sphere light on the GPU (`sphere_rays.wgsl`), the twin
//! of `eye::sphere_rays::sphere_visibility` without its probe: the CPU sets
//! every pixel up in f64 (its two ray origins and its cap frame, relative
//! to the sphere's centre, `GpuSphereStart::new`) and the shared pattern's
//! cap samples (`shared_cap_samples`); the device casts them through the
//! BVH of every triangle relative to the centre (`sphere_bvh`, exact.wgsl's
//! traversal), a chunk of samples per dispatch, as `exact`'s planar rays
//! (`point_rays::cast_point_rays`), and resolves the counts and
//! weights into the visibility and the weighted visibility.

use super::context::Gpu;
use super::dispatch::{module, pipeline, uniform, upload};
use super::exact::ExactParams;
use super::point_rays::{cast_point_rays, PointRays};
use super::refusals::fits;
use crate::error::Result;
use crate::eye::gbuffer::GBuffer;
use crate::eye::sphere_rays::{ray_origins, shared_cap_samples};
use crate::geom::light_shape::sphere::CapFrame;
use crate::geom::light_shape::LightShape;
use crate::geom::sphere_light::SphereLight;
use crate::methods::exact::Bvh;
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
        ..Default::default()
    };
    // The strata of the shared pattern (the unit square's, as the CPU's).
    params.set_light(LightShape::rect([1.0, 1.0]), samples);
    debug_assert_eq!(params.strata(), (na, nb));
    let sphere = SphereParams {
        radius: light.radius as f32,
        ..Default::default()
    };
    let rays = PointRays {
        label: "softshadow eye sphere",
        pipelines: |d| {
            let p = pipelines(d);
            (&p.cast, &p.resolve)
        },
        buffers: |d: &wgpu::Device| {
            let own = vec![
                upload(d, "cap samples", &table),
                uniform(d, "sphere params", &sphere),
            ];
            (upload(d, "sphere starts", &starts), own)
        },
    };
    let ((v, weighted), timings) = cast_point_rays(g, bvh, params, rays, sw)?;
    Ok((
        v.into_iter().zip(weighted).map(|(v, w)| [v, w]).collect(),
        timings,
    ))
}
