//! The eye view: a scene seen through a camera, every mesh casting and
//! receiving shadows (its own included), lit by a rectangle or the sun.
//!
//! Stages (timed): `first_hits` (gbuffer.rs: what each pixel sees),
//! `transform` (the scene to the kernels' light space), then per method
//! what it reads: `exact` traces shadow rays from each surface point
//! (rays.rs); the map methods rasterize occluder layers focused on the
//! visible points (focus.rs) and shade each pixel at its own point and
//! depth with the biases of maps.rs (`extent`, `raster_occluders`,
//! `shadow`). Visibility is 1 where a pixel sees no surface.

pub mod focus;
pub mod gbuffer;
pub mod maps;
pub mod rays;

pub use gbuffer::GBuffer;
pub use maps::{Bias, EyeMaps};

use crate::backend::{Backend, BackendChoice, Run};
use crate::error::{Error, Result};
use crate::geom::camera::Camera;
use crate::geom::light::{check_resolution, MapGrid};
use crate::geom::light_space::{Light, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::geom::sun::SunSpace;
use crate::geom::units::{check_unit, depth_unit, light_size_in};
use crate::methods::config::CallContext;
use crate::methods::{Input, MethodConfig};
use crate::pipeline::{Stopwatch, Timings};
use crate::threads;
use gbuffer::SceneTriangles;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The default biases of the map methods (texels), measured by
/// `benchmarks/bench_bias.py` (docs/benchmarks/bias.md): with no normal
/// offset a depth bias alone leaves acne on 3% of the lit pixels up to 2
/// texels; half a texel of normal offset removes it (0.01%), and every
/// further texel adds light leaking where occluders meet receivers.
pub const DEFAULT_BIAS: Bias = Bias {
    normal_offset: 0.5,
    depth_bias: 0.5,
};
/// The largest bias accepted, in texels.
pub const MAX_BIAS: f64 = 64.0;

impl Bias {
    /// Checks user biases (finite, in [0, MAX_BIAS]); `None` keeps a default.
    pub fn new(normal_offset: Option<f64>, depth_bias: Option<f64>) -> Result<Bias> {
        let check = |arg: &str, v: Option<f64>, d: f64| match v {
            None => Ok(d),
            Some(v) if v.is_finite() && (0.0..=MAX_BIAS).contains(&v) => Ok(v),
            Some(v) => Err(Error::invalid(
                arg,
                format!("must be a number of texels in [0, {MAX_BIAS}], got {v}"),
            )),
        };
        Ok(Bias {
            normal_offset: check("normal_offset", normal_offset, DEFAULT_BIAS.normal_offset)?,
            depth_bias: check("depth_bias", depth_bias, DEFAULT_BIAS.depth_bias)?,
        })
    }
}

/// An image to render.
#[derive(Debug, Clone, Copy)]
pub struct EyeCall<'a> {
    pub meshes: &'a [MeshRef<'a>],
    pub light: &'a Light,
    pub camera: &'a Camera,
    pub method: MethodConfig,
    /// The light-view maps' (W, H); `None`: from the pixels' footprint.
    pub map_resolution: Option<(i64, i64)>,
    pub bias: Bias,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
}

/// A rendered image.
#[derive(Debug, Clone)]
pub struct EyeImage {
    pub gbuffer: GBuffer,
    /// (H, W) visibility; 1 where no surface.
    pub visibility: Vec<f32>,
    /// The map methods' light-view maps (None for `exact`).
    pub maps: Option<EyeMaps>,
    /// The light space they are in.
    pub light_space: LightSpace,
    pub timings: Timings,
}

/// Renders the visibility image of `call` (the CPU: the eye view has no
/// GPU pipeline yet).
pub fn render(call: &EyeCall) -> Result<Run<EyeImage>> {
    let cap = threads::resolve(call.threads)?;
    if let Some(r) = call.map_resolution {
        check_resolution("map_resolution", r)?;
    }
    let backend =
        match call.backend {
            BackendChoice::Cpu | BackendChoice::Auto => Backend::Cpu,
            BackendChoice::Gpu => return Err(Error::invalid(
                "backend",
                "the eye view (render) runs on the CPU only in this version; use backend=\"cpu\"",
            )),
        };
    let ((image, method), threads) = threads::run_capped(cap, || render_cpu(call))?;
    Ok(Run {
        output: image,
        method,
        backend,
        threads,
    })
}

fn render_cpu(call: &EyeCall) -> Result<(EyeImage, MethodConfig)> {
    let mut sw = Stopwatch::new();
    let scene = SceneTriangles::new(call.meshes)?;
    let g = gbuffer::first_hits(call.camera, &scene);
    sw.lap("first_hits");
    let hits = g.hits();
    let points: Vec<[f64; 3]> = hits.iter().map(|&k| g.position[k]).collect();
    let normals: Vec<[f32; 3]> = hits.iter().map(|&k| g.normal[k]).collect();
    let space = match call.light {
        Light::Rect(l) => LightSpace::Rect(*l),
        Light::Sun(s) => {
            let focus: Vec<DVec3> = points.iter().map(|p| DVec3::from_array(*p)).collect();
            let focus = if focus.is_empty() {
                scene.points().collect()
            } else {
                focus
            };
            LightSpace::Sun(SunSpace::fit_focused(
                *s,
                scene.points(),
                focus.into_iter(),
            )?)
        }
    };
    // Kernel light space, in the depth unit of the visible points.
    let pts_ls: Vec<DVec3> = points
        .par_iter()
        .map(|p| space.to_light(DVec3::from_array(*p)))
        .collect();
    let unit = depth_unit(pts_ls.iter().fold(0f64, |m, q| m.max(q.z)));
    check_unit("meshes", unit)?;
    let light_size = light_size_in("size", space.size(), unit)?;
    let corners: Vec<DVec3> = scene
        .corners
        .par_iter()
        .flat_map_iter(|t| t.map(|c| space.to_light(c) / unit))
        .collect();
    sw.lap("transform");

    let mut visibility = vec![1f32; g.len()];
    let mut maps = None;
    let method;
    // A hard light needs one ray: every sample would be the same.
    if call.method.kernel().reads_input(Input::OccluderTriangles) {
        method = call.method.resolve(&CallContext {
            backend: Backend::Cpu,
            resolution: (call.camera.width, call.camera.height),
            depth_layers: None,
        })?;
        let samples = match method.kernel() {
            crate::methods::Method::Exact { samples } if !call.light.is_hard() => samples,
            _ => 1,
        };
        let tris: Vec<[Vec3; 3]> = corners
            .par_chunks(3)
            .map(|c| [c[0].as_vec3(), c[1].as_vec3(), c[2].as_vec3()])
            .collect();
        sw.lap("triangles");
        let v = rays::visibility(&space, unit, light_size, tris, &points, &normals, samples);
        for (&k, v) in hits.iter().zip(v) {
            visibility[k] = v;
        }
        sw.lap("shadow");
    } else if !points.is_empty() {
        let in_front: Vec<DVec3> = pts_ls.iter().copied().filter(|q| q.z > 0.0).collect();
        let pts_unit: Vec<DVec3> = in_front.iter().map(|q| *q / unit).collect();
        let extent = if pts_unit.is_empty() {
            [1.0, 1.0]
        } else {
            focus::focused_extent(&corners, &pts_unit, light_size)?
        };
        let footprint = focus::median(
            hits.iter()
                .zip(&pts_ls)
                .filter(|(_, q)| q.z > 0.0)
                .map(|(&k, q)| {
                    let world = g.depth[k] as f64 / call.camera.focal;
                    match space {
                        LightSpace::Rect(_) => world / q.z,
                        LightSpace::Sun(s) => world / s.lateral_scale(),
                    }
                })
                .collect(),
        )
        .unwrap_or(1.0);
        let fitted = focus::footprint_resolution(extent, footprint);
        let resolution = match call.map_resolution {
            Some((w, h)) => (w as usize, h as usize),
            None => fitted,
        };
        method = call.method.resolve(&CallContext {
            backend: Backend::Cpu,
            resolution,
            depth_layers: None,
        })?;
        // The eye view has occluder maps only: the resolved config's
        // occluder resolution (the fitted one unless the config sets it;
        // "auto"'s rule takes a quarter of it).
        let (w, h) = method.occluder_resolution().unwrap_or(resolution);
        let grid = MapGrid::new(w, h, extent)?;
        sw.lap("extent");
        let tris = maps::LightTriangles {
            verts: corners,
            faces: (0..scene.corners.len() as u32)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
        };
        let (v, m) = maps::shade(
            &space,
            unit,
            light_size,
            &tris,
            grid,
            method.passes(),
            method.kernel(),
            &points,
            &normals,
            &call.bias,
        )?;
        for (&k, v) in hits.iter().zip(v) {
            visibility[k] = v;
        }
        maps = Some(m);
        sw.lap("shadow");
    } else {
        method = call.method.resolve(&CallContext {
            backend: Backend::Cpu,
            resolution: (call.camera.width, call.camera.height),
            depth_layers: None,
        })?;
    }
    // A rectangle lights its n side only.
    if let LightSpace::Rect(l) = space {
        for (&k, p) in hits.iter().zip(&points) {
            if (DVec3::from_array(*p) - l.center).dot(l.n) <= 0.0 {
                visibility[k] = 0.0;
            }
        }
    }
    Ok((
        EyeImage {
            gbuffer: g,
            visibility,
            maps,
            light_space: space,
            timings: sw.timings,
        },
        method,
    ))
}
