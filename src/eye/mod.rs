//! The eye view: a scene seen through a camera, every mesh casting and
//! receiving shadows (its own included), lit by a rectangle or the sun.
//!
//! Stages (timed): `first_hits` (gbuffer.rs: what each pixel sees),
//! `transform` (the scene to the kernels' light space), then per method
//! what it reads: `exact` traces shadow rays from each surface point
//! (rays.rs); the map methods rasterize occluder layers focused on the
//! visible points (focus.rs) and shade each pixel at its own point and
//! depth with the biases of maps.rs (`extent`, `raster_occluders`,
//! `shadow`). Visibility is 1 where a pixel sees no surface. A rectangle
//! lights its n side only: `rays::plane_side` has no side for a point at
//! or behind its plane, which exact (no ray start) and the map methods (the
//! tangent-plane bound) both turn into 0.
//!
//! Every backend's visibility is then shaded on the CPU (shading.rs:
//! Lambertian direct lighting, unshadowed and times the visibility) by
//! `render_shaded`, so both backends shade a visibility alike.
//!
//! Both backends run the same stages: `render_cpu` here, and its GPU twin
//! `crate::gpu::render_gpu` (src/gpu/eye.rs), which casts the first hits,
//! the shadow rays, the occluder layers and the gather on the device and
//! shares the framing below (`frame`, `map_grid`, ...) with the CPU.

mod casters;
pub mod focus;
pub mod gbuffer;
pub mod maps;
pub mod rays;
pub mod shading;
pub mod shadow_mapping;
pub mod tangent_plane;

pub use gbuffer::GBuffer;
pub use maps::{Bias, EyeMaps};
pub use shading::{Lighting, Shaded};

use crate::backend::{Backend, BackendChoice, Run};
use crate::error::{Error, Result};
use crate::geom::camera::Camera;
use crate::geom::light::{check_resolution, MapGrid};
use crate::geom::light_space::{Light, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::geom::sun::SunSpace;
use crate::geom::units::{check_unit, depth_unit, light_size_in};
use crate::methods::config::CallContext;
use crate::methods::MethodConfig;
use crate::pipeline::{Stopwatch, Timings};
use crate::threads;
use gbuffer::SceneTriangles;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::borrow::Cow;

/// The default biases of the map methods (texels), measured by
/// `benchmarks/bench_bias.py` (docs/benchmarks/bias.md) on the four
/// eye-view scenes: without either bias up to 55% of the lit pixels shadow
/// themselves; a quarter texel of normal offset and half a texel of depth
/// bias bring that to 0.3% (the map's penumbra edges), and every further
/// texel of either lets more light leak into the shadows.
pub const DEFAULT_BIAS: Bias = Bias {
    normal_offset: 0.25,
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

/// Renders the visibility image of `call` on the backend it asks for:
/// "auto" takes the GPU where `crate::backend` would (a real, non-software
/// adapter, a config that resolves there) and the light is not hard (the
/// GPU has no hard shadow map kernel for the map methods; ShadowMapping
/// takes any light).
pub fn render(call: &EyeCall) -> Result<Run<EyeImage>> {
    let cap = threads::resolve(call.threads)?;
    if let Some(r) = call.map_resolution {
        check_resolution("map_resolution", r)?;
    }
    let backend = match call.backend {
        BackendChoice::Cpu => Backend::Cpu,
        BackendChoice::Gpu => Backend::Gpu,
        BackendChoice::Auto => {
            let gpu = CallContext {
                backend: Backend::Gpu,
                resolution: (call.camera.width, call.camera.height),
                depth_layers: None,
                eye: true,
            };
            // ShadowMapping is a hard shadow: it takes hard lights on the GPU.
            let hard_ok = matches!(call.method, MethodConfig::ShadowMapping(_));
            if crate::backend::real_gpu()
                && (hard_ok || !call.light.is_hard())
                && call.method.resolve(&gpu).is_ok()
            {
                Backend::Gpu
            } else {
                Backend::Cpu
            }
        }
    };
    // A target plans the setting (`methods/plan.rs`, `plan_eye`); the
    // planned config then runs as if the user had given it.
    let t0 = std::time::Instant::now();
    let mut plan = match call.method {
        MethodConfig::Auto(given, target) if !target.is_none() => Some(
            crate::methods::plan::plan_eye(&target, MethodConfig::Auto(given, Default::default())),
        ),
        _ => None,
    };
    let planned = EyeCall {
        method: plan.as_ref().map_or(call.method, |p| p.config),
        ..*call
    };
    let planning = t0.elapsed().as_secs_f64();
    let ((mut image, method), threads) = threads::run_capped(cap, || match backend {
        Backend::Cpu => render_cpu(&planned),
        #[cfg(feature = "gpu")]
        Backend::Gpu => crate::gpu::render_gpu(&planned),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    })?;
    if let Some(p) = plan.as_mut() {
        p.decisions.push(focus_decision(&image));
        p.config = method;
        image.timings.insert(0, ("plan", planning));
    }
    Ok(Run {
        output: image,
        method,
        backend,
        threads,
        plan,
    })
}

/// `render`, then the direct lighting of every pixel under `lighting`
/// (shading.rs) on the CPU whatever the backend, timed as `shading`.
/// `lighting` is checked against the call's light and meshes
/// (`Lighting::new`).
pub fn render_shaded(call: &EyeCall, lighting: &Lighting) -> Result<(Run<EyeImage>, Shaded)> {
    if lighting.albedo.len() != call.meshes.len() {
        return Err(Error::shape(
            "albedo",
            format!(
                "{} albedos for {} meshes",
                lighting.albedo.len(),
                call.meshes.len()
            ),
        ));
    }
    let cap = threads::resolve(call.threads)?;
    let mut run = render(call)?;
    let t0 = std::time::Instant::now();
    let img = &run.output;
    let (shaded, _) = threads::run_capped(cap, || {
        Ok(shading::shade(
            call.light,
            lighting,
            &img.gbuffer,
            &img.visibility,
        ))
    })?;
    run.output
        .timings
        .push(("shading", t0.elapsed().as_secs_f64()));
    Ok((run, shaded))
}

/// What the eye view shades, reported in a plan: light-view texels only
/// where pixels need them (the maps fitted to the visible points, focus.rs),
/// or shadow rays from the visible pixels only.
fn focus_decision(image: &EyeImage) -> crate::methods::plan::Decision {
    let pixels = image.gbuffer.hits().len();
    let why = match &image.maps {
        Some(m) => format!(
            "light-view maps {}x{} over the light-space bounds of the {pixels} visible points \
             only, at about one texel a pixel's footprint",
            m.grid.width, m.grid.height
        ),
        None => format!("shadow rays from the {pixels} pixels that see a surface only"),
    };
    crate::methods::plan::Decision {
        name: "focus",
        taken: true,
        why,
    }
}

/// What both backends derive from the G-buffer before shading: the visible
/// points, the light space fitted to them, the depth unit and every
/// triangle's corners in kernel light space.
pub(crate) struct Framed {
    /// Flat indices of the pixels that see a surface, and their world points
    /// and camera-facing normals.
    pub hits: Vec<usize>,
    pub points: Vec<[f64; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub space: LightSpace,
    /// The visible points in light space (not unit-scaled).
    pub pts_ls: Vec<DVec3>,
    /// The kernels' depth unit, and the light's size in it.
    pub unit: f64,
    pub light_size: [f64; 2],
    /// Every vertex in kernel light space, unit-scaled (the faces into them
    /// are `SceneTriangles::faces`).
    pub verts: Vec<DVec3>,
}

/// The light space, depth unit and light-space triangles of an image whose
/// G-buffer is `g`.
pub(crate) fn frame(call: &EyeCall, scene: &SceneTriangles, g: &GBuffer) -> Result<Framed> {
    let hits = g.hits();
    let points: Vec<[f64; 3]> = hits.par_iter().map(|&k| g.position[k]).collect();
    let normals: Vec<[f32; 3]> = hits.par_iter().map(|&k| g.normal[k]).collect();
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
    let unit = depth_unit(pts_ls.par_iter().map(|q| q.z).reduce(|| 0.0, f64::max));
    check_unit("meshes", unit)?;
    let light_size = light_size_in("size", space.size(), unit)?;
    let verts: Vec<DVec3> = scene
        .vertices
        .par_iter()
        .map(|&c| space.to_light(c) / unit)
        .collect();
    Ok(Framed {
        hits,
        points,
        normals,
        space,
        pts_ls,
        unit,
        light_size,
        verts,
    })
}

/// The most points the median pixel footprint is taken over (focus.rs).
const FOOTPRINT_SAMPLES: usize = 1 << 14;

/// The config of a call that reads no maps (`exact`, or no visible point),
/// resolved for `backend` at the camera's resolution.
pub(crate) fn resolve_at_camera(call: &EyeCall, backend: Backend) -> Result<MethodConfig> {
    call.method.resolve(&CallContext {
        backend,
        resolution: (call.camera.width, call.camera.height),
        depth_layers: None,
        eye: true,
    })
}

/// Light samples per pixel of `exact`: a hard light needs one ray (every
/// sample would be the same).
pub(crate) fn exact_samples(call: &EyeCall, method: &MethodConfig) -> u32 {
    match method.kernel() {
        crate::methods::Method::Exact { samples } if !call.light.is_hard() => samples,
        _ => 1,
    }
}

/// The triangles `exact` traces: the corners in f32.
pub(crate) fn traced_triangles(f: &Framed, scene: &SceneTriangles) -> Vec<[Vec3; 3]> {
    scene
        .faces
        .par_iter()
        .map(|t| t.map(|i| f.verts[i as usize].as_vec3()))
        .collect()
}

/// The faces of the meshes that can shadow a visible point (`casters.rs`):
/// the map methods' occluders. Smoothies keep every mesh: their falloff
/// reads the depth of the receiver behind each silhouette from the map
/// (without the floor there, its error on contact_boxes went from under
/// 0.1 to 0.26).
pub(crate) fn casting_faces<'s>(
    call: &EyeCall,
    scene: &'s SceneTriangles,
    f: &Framed,
    g: &GBuffer,
) -> Cow<'s, [[u32; 3]]> {
    if matches!(
        call.method.kernel(),
        crate::methods::Method::Smoothies { .. }
    ) {
        return Cow::Borrowed(&scene.faces);
    }
    let point_mesh: Vec<i32> = f.hits.iter().map(|&k| g.mesh_id[k]).collect();
    let casts = casters::casters(scene, call.light, &f.points, &point_mesh);
    scene
        .faces
        .iter()
        .zip(&scene.mesh_of)
        .filter(|(_, &m)| casts[m as usize])
        .map(|(t, _)| *t)
        .collect::<Vec<_>>()
        .into()
}

/// The map methods' occluder grid (focused on what the occluders `faces`
/// can shadow of the visible points, sized from their footprint unless the
/// call sets it) and the config resolved for `backend` at that resolution.
/// `f` has visible points.
pub(crate) fn map_grid(
    call: &EyeCall,
    g: &GBuffer,
    f: &Framed,
    faces: &[[u32; 3]],
    backend: Backend,
) -> Result<(MapGrid, MethodConfig)> {
    let visible = focus::VisibleBounds::of(&f.pts_ls, f.unit);
    let mut used = vec![false; f.verts.len()];
    for t in faces {
        for &i in t {
            used[i as usize] = true;
        }
    }
    // Every vertex in use (Smoothies, or every mesh can cast): no copy.
    let occluders: Cow<[DVec3]> = if used.iter().all(|&u| u) {
        Cow::Borrowed(&f.verts)
    } else {
        f.verts
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(q, _)| *q)
            .collect()
    };
    let extent = match &visible {
        None => [1.0, 1.0],
        Some(v) => focus::focused_extent(&occluders, v, f.light_size)?,
    };
    // The median over a regular subsample of at most FOOTPRINT_SAMPLES
    // points: the resolution is a rule of thumb, not worth a full select.
    let stride = f.hits.len().div_ceil(FOOTPRINT_SAMPLES).max(1);
    let footprint = focus::median(
        f.hits
            .iter()
            .zip(&f.pts_ls)
            .step_by(stride)
            .filter(|(_, q)| q.z > 0.0)
            .map(|(&k, q)| {
                let world = g.depth[k] as f64 / call.camera.focal;
                match f.space {
                    LightSpace::Rect(_) => world / q.z,
                    LightSpace::Sun(s) => world / s.lateral_scale(),
                }
            })
            .collect(),
    )
    .unwrap_or(1.0);
    let fitted = focus::footprint_resolution(
        extent,
        focus::capped_footprint(extent, footprint, f.hits.len()),
    );
    let resolution = match call.map_resolution {
        Some((w, h)) => (w as usize, h as usize),
        None => fitted,
    };
    let method = call.method.resolve(&CallContext {
        backend,
        resolution,
        depth_layers: None,
        eye: true,
    })?;
    // The eye view has occluder maps only: the resolved config's
    // occluder resolution (the fitted one unless the config sets it;
    // "auto"'s rule takes a quarter of it).
    let (w, h) = method.occluder_resolution().unwrap_or(resolution);
    Ok((MapGrid::new(w, h, extent)?, method))
}

/// The occluders `faces` as one indexed mesh in kernel light space (the map
/// methods' occluders), its vertices taken out of `f`.
pub(crate) fn light_triangles<'s>(
    f: &mut Framed,
    faces: &'s [[u32; 3]],
) -> maps::LightTriangles<'s> {
    maps::LightTriangles {
        verts: std::mem::take(&mut f.verts),
        faces,
    }
}

fn render_cpu(call: &EyeCall) -> Result<(EyeImage, MethodConfig)> {
    let mut sw = Stopwatch::new();
    let scene = SceneTriangles::new(call.meshes)?;
    let g = gbuffer::first_hits(call.camera, &scene);
    sw.lap("first_hits");
    if let MethodConfig::ShadowMapping(cfg) = call.method {
        let method = resolve_at_camera(call, Backend::Cpu)?;
        let (visibility, _map) = shadow_mapping::render(call, &cfg, &scene, &g, &mut sw)?;
        let image = shadow_mapping::image(call, &scene, g, visibility, sw.timings)?;
        return Ok((image, method));
    }
    let mut f = frame(call, &scene, &g)?;
    sw.lap("transform");

    let mut visibility = vec![1f32; g.len()];
    let mut maps = None;
    let method;
    if call.method.kernel().traces() {
        method = resolve_at_camera(call, Backend::Cpu)?;
        let samples = exact_samples(call, &method);
        let tris = traced_triangles(&f, &scene);
        sw.lap("triangles");
        let starts = rays::ray_starts(&f.space, f.unit, &f.points, &f.normals);
        let order = rays::tiled(&f.hits, call.camera.width, call.camera.height);
        let v = rays::visibility(f.light_size, tris, &starts, &order, samples);
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
        sw.lap("shadow");
    } else if !f.points.is_empty() {
        let casting = casting_faces(call, &scene, &f, &g);
        let (grid, m) = map_grid(call, &g, &f, &casting, Backend::Cpu)?;
        method = m;
        sw.lap("extent");
        let tris = light_triangles(&mut f, &casting);
        let (v, m) = maps::shade(
            &f.space,
            f.unit,
            f.light_size,
            &tris,
            grid,
            method.passes(),
            method.kernel(),
            &f.points,
            &f.pts_ls,
            &f.normals,
            &call.bias,
            &mut sw,
        )?;
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
        maps = Some(m);
        sw.lap("maps_out");
    } else {
        method = resolve_at_camera(call, Backend::Cpu)?;
    }
    Ok((
        EyeImage {
            gbuffer: g,
            visibility,
            maps,
            light_space: f.space,
            timings: sw.timings,
        },
        method,
    ))
}
