//! The use cases, each on the backend it runs on: light-view maps of meshes
//! (`shadow_map`, planned by `crate::auto` for a target), of a scene
//! shadowing itself (`scene_shadow_map`), of the user's depth maps
//! (`shadow_map_from_depth`), visibility at world points (`sample_points`)
//! and the eye view (`render`, `render_shaded`). A Rust user calls these
//! with a typed config and a [`BackendChoice`]; the bindings only convert.
//!
//! Every call resolves its method config here, against the backend that will
//! run it (the GPU has no hierarchy and sums in f32 only), and runs on the
//! worker threads `threads.rs` allows.

use crate::backend::{Backend, BackendChoice};
use crate::error::{Error, Result};
use crate::error_estimate::Draw;
use crate::eye::albedo::{albedo_image, Material};
use crate::eye::{EyeCall, EyeImage, Lighting, Shaded, MAX_LIGHTS};
use crate::frame::{orthographic_maps, MapSettings, ShadowResult};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::{sphere_has_no_space, Light, LightSpace};
use crate::geom::mesh::MeshRef;
use crate::methods::config::{check_resolution, CallContext};
use crate::methods::AutoConfig;
use crate::methods::MethodConfig;
use crate::pipeline;
use crate::threads;
use crate::timing::Timings;

/// The backend that runs a call: "auto" takes a real GPU where the config
/// resolves there (`gpu`: the call's context on the GPU) and the light is
/// one the GPU kernels take (`light_ok`).
fn pick(choice: BackendChoice, method: &MethodConfig, gpu: CallContext, light_ok: bool) -> Backend {
    match choice {
        BackendChoice::Cpu => Backend::Cpu,
        BackendChoice::Gpu => Backend::Gpu,
        BackendChoice::Auto => {
            if real_gpu() && light_ok && method.resolve(&gpu).is_ok() {
                Backend::Gpu
            } else {
                Backend::Cpu
            }
        }
    }
}

/// What "auto" runs for a disk in the light view: `bitmask`, the closer of
/// the two map methods that shade a disk (on the disk of
/// tests/eye_view/test_lights.py at 256² maps: 0.0038 against `ssm`'s
/// 0.0076 over the shadowed pixels).
fn light_view_disk() -> MethodConfig {
    MethodConfig::Bitmask(crate::methods::BitmaskConfig::default())
}

/// The config a call on `light` runs. A rectangle, the sun and a disk take
/// every method (`exact` and `bitmask` sample the disk, `ssm` clips its
/// micro-patches to it, PCSS filters over the ellipse inscribed in its box,
/// the smoothies' width is its diameter, ShadowMapping reads its centre); a
/// sphere, which has no light space, `exact` only, any other method refused
/// naming `method` and why. "auto" without a target runs `auto` (the eye
/// view's `exact` default; in the light view `bitmask`). A target stays in
/// the eye view for a disk and a sphere (`plan_eye` plans `exact` for them)
/// and is refused in the light view, whose planner plans the rectangle's
/// maps (a sphere has no light view at all).
fn for_light(
    method: MethodConfig,
    light: &Light,
    auto: MethodConfig,
    eye: bool,
) -> Result<MethodConfig> {
    let shape = light.kernel_shape();
    if matches!(shape, LightShape::Rect { .. }) {
        return Ok(method);
    }
    let name = light.name();
    if let Light::Sphere(_) = light {
        return match method {
            MethodConfig::Exact(_) => Ok(method),
            MethodConfig::Auto(a) if a.target.is_none() => Ok(auto),
            // A target plans `exact` by its error law and checks the run's
            // estimate (`pipeline::eye_view::render_sphere`), in the eye
            // view; a sphere has no light view.
            MethodConfig::Auto(_) if eye => Ok(method),
            MethodConfig::Auto(_) | MethodConfig::ShadowMapping(_) => Err(sphere_has_no_space()),
            m => Err(Error::invalid(
                "method",
                format!(
                    "{:?} cannot shade a SphereLight: it projects occluders onto a light's \
                     plane, which a sphere has not; a sphere runs with \"exact\"",
                    m.name()
                ),
            )),
        };
    }
    match method {
        MethodConfig::Auto(a) if a.target.is_none() => Ok(auto),
        MethodConfig::Auto(_) if eye => Ok(method),
        MethodConfig::Auto(_) => Err(Error::invalid(
            "method",
            format!(
                "Auto with a target plans light-view maps, which a {name} does not take; pass \
                 method=\"exact\" (Exact(samples=...))"
            ),
        )),
        m => Ok(m),
    }
}

/// Whether a real (non-software) GPU adapter opens: what "auto" needs.
#[cfg(feature = "gpu")]
pub(crate) fn real_gpu() -> bool {
    crate::gpu::info().is_ok_and(|i| !i.software)
}

#[cfg(not(feature = "gpu"))]
pub(crate) fn real_gpu() -> bool {
    false
}

/// A call's output with what ran it.
#[derive(Debug, Clone)]
pub struct Run<T> {
    pub output: T,
    /// The config that ran ("auto" resolved, every default filled in).
    pub method: MethodConfig,
    pub backend: Backend,
    /// Worker threads the CPU stages could use.
    pub threads: usize,
    /// What `Auto` with a target decided (light-view maps from meshes).
    pub plan: Option<crate::auto::Plan>,
}

/// A shadow map of meshes: what to compute and where.
#[derive(Debug, Clone, Copy)]
pub struct MeshCall<'a> {
    pub occluders: MeshRef<'a>,
    pub receivers: MeshRef<'a>,
    pub light: &'a Light,
    /// Output (W, H).
    pub resolution: (i64, i64),
    /// Tangent half-extents, or `None` to fit them.
    pub extent: Option<[f64; 2]>,
    pub method: MethodConfig,
    pub backend: BackendChoice,
    /// Worker threads; `None`: SOFTSHADOW_THREADS, else all cores.
    pub threads: Option<i64>,
    /// Estimate the result's error from exact rays at texels drawn as it
    /// says (`crate::light_view::estimate`); None: no estimate (`Auto`
    /// with a target always estimates, from a fixed draw).
    pub estimate_error: Option<Draw>,
}

/// Meshes -> light-view maps -> visibility, on the chosen backend.
pub fn shadow_map(call: &MeshCall) -> Result<Run<ShadowResult>> {
    let (w, h) = check_resolution("resolution", call.resolution)?;
    let call = &MeshCall {
        method: for_light(call.method, call.light, light_view_disk(), false)?,
        ..*call
    };
    let cap = threads::resolve(call.threads)?;
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (w, h),
        depth_layers: None,
        eye: false,
    };
    let gpu = CallContext {
        backend: Backend::Gpu,
        ..ctx
    };
    let backend = pick(
        call.backend,
        &call.method,
        gpu,
        !call.light.kernel_shape().is_point(),
    );
    let ctx = CallContext { backend, ..ctx };
    let target = match call.method {
        MethodConfig::Auto(a) if !a.target.is_none() => Some(a.target),
        _ => None,
    };
    let method = call.method.resolve(&ctx)?;
    let ((output, method, plan), threads) = threads::run_capped(cap, || {
        let space = mesh_space(
            call.light,
            &[("occluders", call.occluders), ("receivers", call.receivers)],
        )?;
        // A sun's map extent is given in world units; the kernels' in tangents.
        let extent = call.extent.map(|e| space.kernel_extent(e));
        // `Auto` with a target always says how right it is, from a fixed
        // draw (its refinements must not depend on the machine's speed).
        let estimate = if target.is_some() {
            Some(Draw::Fixed)
        } else {
            call.estimate_error
        };
        let run =
            |method: &MethodConfig, hard: bool, size: (usize, usize), extent: Option<[f64; 2]>| {
                let mut settings = MapSettings::new(size.0, size.1, extent, method);
                settings.hard = hard;
                settings.estimate = estimate;
                pipeline::from_meshes(call.occluders, call.receivers, &space, &settings, backend)
            };
        let Some(target) = target else {
            return Ok((run(&method, false, (w, h), extent)?, method, None));
        };
        let (first, cfg, plan) = crate::auto::driver::planned(
            (call.occluders, call.receivers),
            &call.method,
            &space,
            extent,
            &ctx,
            &target,
            run,
        )?;
        let Some(mut plan) = plan else {
            return Ok((first, cfg, None));
        };
        // An error target is checked against the run's own estimate and
        // the call run again with `exact` until it is met (`auto/refine.rs`).
        let planning = first.timings.iter().find(|t| t.0 == "plan").map(|t| t.1);
        let mut refinements = vec![];
        let (mut out, method, replaced) = match target.error {
            Some(e) => {
                let seconds = first
                    .timings
                    .iter()
                    .filter(|t| t.0 != "plan")
                    .map(|t| t.1)
                    .sum();
                crate::auto::refine::refined(
                    e.0,
                    crate::auto::plan::LIGHT_REFINE,
                    ((first, cfg), seconds),
                    &mut refinements,
                    |r: &ShadowResult| r.estimate,
                    |m| {
                        let m = m.resolve(&ctx)?;
                        Ok((run(&m, false, (w, h), extent)?, m))
                    },
                )?
            }
            None => (first, cfg, 0.0),
        };
        let verdict = refinements.pop_if(|d| d.name == "target");
        plan.decisions.extend(refinements);
        if let Some(e) = &out.estimate {
            plan.decisions.push(estimate_decision(e, "texels"));
        }
        plan.decisions.extend(verdict);
        plan.config = method;
        plan.planned = (method != cfg).then_some(cfg);
        if replaced > 0.0 {
            out.timings.insert(0, ("replaced", replaced));
            if let Some(p) = planning {
                out.timings.insert(0, ("plan", p));
            }
        }
        Ok((out, method, Some(plan)))
    })?;
    Ok(Run {
        output,
        method,
        backend,
        threads,
        plan,
    })
}

/// A shadow map of a scene where every mesh casts and receives shadows.
#[derive(Debug, Clone, Copy)]
pub struct SceneCall<'a> {
    /// Every mesh, as one.
    pub scene: MeshRef<'a>,
    pub light: &'a Light,
    pub resolution: (i64, i64),
    pub extent: Option<[f64; 2]>,
    pub method: MethodConfig,
    /// The map methods' self-shadowing biases (see `eye/maps.rs`).
    pub bias: crate::eye::Bias,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
    /// As `MeshCall::estimate_error`.
    pub estimate_error: Option<Draw>,
}

/// A self-shadowing scene -> light-view maps -> visibility (the CPU: its
/// receiver texels are shaded as points, which the GPU twin of the eye view
/// does not cover yet).
pub fn scene_shadow_map(call: &SceneCall) -> Result<Run<ShadowResult>> {
    let (w, h) = check_resolution("resolution", call.resolution)?;
    let call = &SceneCall {
        method: for_light(call.method, call.light, light_view_disk(), false)?,
        ..*call
    };
    let cap = threads::resolve(call.threads)?;
    if call.backend == BackendChoice::Gpu {
        return Err(Error::invalid(
            "backend",
            "the light-view maps of a scene shadowing itself run on the CPU only in this version; \
             use backend=\"cpu\"",
        ));
    }
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (w, h),
        depth_layers: None,
        eye: false,
    };
    let method = call.method.resolve(&ctx)?;
    let (output, threads) = threads::run_capped(cap, || {
        let space = mesh_space(call.light, &[("meshes", call.scene)])?;
        let extent = call.extent.map(|e| space.kernel_extent(e));
        let mut settings = MapSettings::new(w, h, extent, &method);
        settings.estimate = call.estimate_error;
        pipeline::from_scene(call.scene, &space, &settings, &call.bias)
    })?;
    Ok(Run {
        output,
        method,
        backend: Backend::Cpu,
        threads,
        plan: None,
    })
}

/// The light space of a scene made of `meshes` (each with the name errors
/// give it): a sun's depth origin and range are fitted to their vertices
/// (checked first: a non-finite vertex is named, not folded into the bounds).
pub fn mesh_space(light: &Light, meshes: &[(&str, MeshRef)]) -> Result<LightSpace> {
    if let Light::Sun(_) = light {
        for (arg, m) in meshes {
            m.validate(arg)?;
        }
    }
    let verts = meshes
        .iter()
        .flat_map(|(_, m)| m.vertices.iter())
        .map(|p| glam::DVec3::from_array(*p));
    light.space_for(verts)
}

/// Depth maps the user rendered: what to shade and where.
#[derive(Debug, Clone, Copy)]
pub struct DepthCall<'a> {
    /// The receiver map's grid, which the output shares.
    pub grid: MapGrid,
    /// The occluder maps' grid (same extent, their own resolution).
    pub occluder_grid: MapGrid,
    /// The light's shape (a rectangle's) in the depths' unit; ignored for
    /// orthographic maps.
    pub light_shape: LightShape,
    /// `Some(angular_size)`: orthographic maps of a directional light of
    /// that angular size (degrees): depths from the depth origin, extents
    /// in world units (see `geom/sun.rs`).
    pub sun: Option<[f64; 2]>,
    pub front: &'a [f32],
    pub back: Option<&'a [f32]>,
    pub receiver: &'a [f32],
    pub method: MethodConfig,
    pub backend: BackendChoice,
    pub threads: Option<i64>,
}

/// What shading depth maps returns.
#[derive(Debug, Clone)]
pub struct DepthOutput {
    pub visibility: Vec<f32>,
    pub timings: Timings,
    /// For orthographic maps: the depth range their kernel space used
    /// (`ShadowMap.sample` rebuilds the space from it).
    pub depth_range: Option<f64>,
}

/// Depth maps -> visibility, on the chosen backend.
pub fn shadow_map_from_depth(call: &DepthCall) -> Result<Run<DepthOutput>> {
    let cap = threads::resolve(call.threads)?;
    // Orthographic maps: the same shading on their kernel-space twins.
    let ortho = call
        .sun
        .map(|a| {
            orthographic_maps(
                (&call.grid, &call.occluder_grid),
                call.front,
                call.back,
                call.receiver,
                a,
            )
        })
        .transpose()?;
    let (grid, occluder_grid, light_shape) = match &ortho {
        Some((_, g, og, size, _)) => (*g, *og, *size),
        None => (
            call.grid,
            call.occluder_grid,
            call.light_shape.check("light_size")?,
        ),
    };
    let (front, receiver, back) = match &ortho {
        Some((.., m)) => (&m[0][..], &m[1][..], m.get(2).map(|b| &b[..])),
        None => (call.front, call.receiver, call.back),
    };
    let layers = 1 + back.is_some() as u32;
    let og = &occluder_grid;
    let ctx = CallContext {
        backend: Backend::Cpu,
        resolution: (grid.width, grid.height),
        depth_layers: Some((layers, (og.width, og.height))),
        eye: false,
    };
    let gpu = CallContext {
        backend: Backend::Gpu,
        ..ctx
    };
    let backend = pick(call.backend, &call.method, gpu, !light_shape.is_point());
    let method = call.method.resolve(&CallContext { backend, ..ctx })?;
    let kernel = method.kernel();
    let maps = pipeline::DepthMaps {
        grid: &grid,
        occluder_grid: og,
        light_shape,
        front,
        back,
        receiver,
    };
    let ((visibility, timings), threads) =
        threads::run_capped(cap, || pipeline::from_depth(&maps, kernel, backend))?;
    let output = DepthOutput {
        visibility,
        timings,
        depth_range: ortho.map(|(space, ..)| space.depth_range),
    };
    Ok(Run {
        output,
        method,
        backend,
        threads,
        plan: None,
    })
}

/// Visibility at world points from a shadow map's occluders (the CPU: points
/// are few and scattered). `method` is the config the map ran with.
pub fn sample_points(
    grid: &MapGrid,
    light: &LightSpace,
    occluders: pipeline::OccluderSource,
    points: &[[f64; 3]],
    method: &MethodConfig,
    threads: Option<i64>,
) -> Result<(Vec<f32>, Vec<bool>)> {
    let cap = threads::resolve(threads)?;
    let kernel = method.kernel();
    threads::run_capped(cap, || {
        pipeline::sample_points(grid, light, occluders, points, kernel)
    })
    .map(|(v, _)| v)
}

/// Renders the visibility image of `call` on the backend it asks for:
/// "auto" takes the GPU where the light view would (a real, non-software
/// adapter, a config that resolves there) and the light is not hard (the
/// GPU has no hard shadow map kernel for the map methods; ShadowMapping
/// takes any light).
pub fn render(call: &EyeCall) -> Result<Run<EyeImage>> {
    let cap = threads::resolve(call.threads)?;
    if let Light::Sphere(s) = call.light {
        if !s.is_outside(call.camera.eye) {
            return Err(Error::invalid(
                "light",
                format!(
                    "the camera's eye {:?} lies inside the SphereLight (centre {:?}, radius {}): \
                     it would see only the light",
                    call.camera.eye.to_array(),
                    s.center.to_array(),
                    s.radius
                ),
            ));
        }
    }
    if let Some(r) = call.map_resolution {
        check_resolution("map_resolution", r)?;
    }
    let gpu = CallContext {
        backend: Backend::Gpu,
        resolution: (call.camera.width, call.camera.height),
        depth_layers: None,
        eye: true,
    };
    // ShadowMapping is a hard shadow: it takes hard lights on the GPU. A
    // sphere's rays run on the GPU when asked (backend="gpu"), without the
    // CPU's probe and not yet timed on a real GPU: "auto" keeps the CPU.
    let hard_ok = matches!(call.method, MethodConfig::ShadowMapping(_));
    let backend = pick(
        call.backend,
        &call.method,
        gpu,
        (hard_ok || !call.light.is_hard()) && !matches!(call.light, Light::Sphere(_)),
    );
    // The default call (`Auto`, nothing given) traces (`eye_default`).
    let default = MethodConfig::Auto(AutoConfig::default());
    let traced = crate::methods::auto_config::eye_default(backend);
    let call = &EyeCall {
        method: if call.method == default {
            MethodConfig::Exact(traced)
        } else {
            for_light(call.method, call.light, MethodConfig::Exact(traced), true)?
        },
        ..*call
    };
    // A target plans the setting (`auto/plan.rs`, `plan_eye`); the
    // planned config then runs as if the user had given it.
    let t0 = std::time::Instant::now();
    let mut plan = match call.method {
        MethodConfig::Auto(a) if !a.target.is_none() => Some(crate::auto::plan_eye(
            &a.target,
            MethodConfig::Auto(AutoConfig {
                target: Default::default(),
                ..a
            }),
            call.light.name(),
            // The rule's maps' error was measured under rectangles (and
            // the sun) only: not under a disk, nor a sphere (whose kernel
            // shape is its silhouette's disk; it has no plane for maps).
            matches!(call.light.kernel_shape(), LightShape::Rect { .. }),
        )),
        _ => None,
    };
    // `Auto` with a target always says how right it is, from a fixed draw
    // of pixels (its refinements must not depend on the machine's speed).
    // The default call (`Auto` without one) does not unless asked: the
    // estimate's first batch alone is 12-19% of a fast call
    // (docs/accuracy.md).
    let planned = EyeCall {
        method: plan.as_ref().map_or(call.method, |p| p.config),
        estimate_error: if plan.is_some() {
            Some(crate::error_estimate::Draw::Fixed)
        } else {
            call.estimate_error
        },
        ..*call
    };
    let planning = t0.elapsed().as_secs_f64();
    // An error target is checked against the run's own estimate and the
    // call run again until it is met (`auto/refine.rs`).
    let error = match call.method {
        MethodConfig::Auto(a) => a.target.error.map(|e| e.0),
        _ => None,
    };
    // `exact` runs of a call with a target share their first hits, framing
    // and BVH: a pilot or a refinement pays for its rays and its estimate
    // only. A call without one runs once and keeps nothing (no G-buffer
    // copy).
    let mut traced = None;
    let mut run = |m: &MethodConfig| {
        let c = EyeCall {
            method: probed(*m, error.is_some(), backend),
            ..planned
        };
        match error {
            Some(_) => pipeline::eye_view::render_reusing(&c, backend, &mut traced),
            None => pipeline::eye_view::render(&c, backend),
        }
    };
    let mut refinements = vec![];
    let mut first_config = None;
    let (((mut image, method), replaced), threads) = threads::run_capped(cap, || {
        let t = std::time::Instant::now();
        let first = run(&planned.method)?;
        first_config = Some(first.1);
        let Some(e) = error else {
            return Ok((first, 0.0));
        };
        let seconds = t.elapsed().as_secs_f64();
        let (image, method, replaced) = crate::auto::refine::refined(
            e,
            crate::auto::plan::EYE_EXACT,
            (first, seconds),
            &mut refinements,
            |img: &EyeImage| img.estimate,
            &mut run,
        )?;
        Ok(((image, method), replaced))
    })?;
    if let Some(p) = plan.as_mut() {
        let verdict = refinements.pop_if(|d| d.name == "target");
        p.decisions.extend(refinements);
        p.decisions.push(focus_decision(&image));
        if let Some(e) = &image.estimate {
            p.decisions.push(estimate_decision(e, "pixels"));
        }
        p.decisions.extend(verdict);
        p.config = method;
        p.planned = first_config.filter(|&c| c != method);
        if replaced > 0.0 {
            image.timings.insert(0, ("replaced", replaced));
        }
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

/// The `exact` runs an error target plans on the CPU trace behind the
/// default call's probe (`auto_config::eye_default`) where they have more
/// samples than it and fewer than `PLANNED_MASKS_FROM`: only the pixels it
/// is unsure of decide them all (by the engine `ExactConfig::engine_for`
/// picks: the masks from `MASKS_FROM`, as the default call's). From
/// `PLANNED_MASKS_FROM` samples they run the masks on every pixel, with no
/// probe to miss a sliver: on the sixteen
/// as-built scenes at 320x240 the masks took 1.8-7.2x less time than the
/// probe and the rays at 1024 samples and 2.9-14x less at 2500, where the
/// probe's answer differed from theirs on up to 1.5% of the pixels by up to
/// 0.05; at 640x480 1.4-5.7x and 2.2-11x (docs/benchmarks/masks_*.md).
/// Against the probe with the masks behind it they took 0.81-1.29x its
/// time at 1024 and 0.66-1.18x at 2500 (0.76-1.16x and 0.61-1.17x at
/// 640x480), more on eight to twelve scenes: what this rule buys is the
/// answer without the probe's misses, not time.
/// Below it the probe stays, the masks behind it: at 256 samples the
/// masks on every pixel took more time than the probe and the rays on
/// torus_on_slab (1.07x at 640x480), mesh_125k (1.45x) and mesh_2m
/// (1.36x), whose dense meshes
/// cost the masks their budget where the probe finds the pixel lit or
/// hidden in 16 rays. A config the user gave runs as given.
const PLANNED_MASKS_FROM: u32 = 1024;

fn probed(m: MethodConfig, planned: bool, backend: Backend) -> MethodConfig {
    use crate::methods::auto_config::EYE_PROBE;
    match m {
        MethodConfig::Exact(c)
            if planned
                && backend == Backend::Cpu
                && c.probe.is_none()
                && c.engine.is_none()
                && c.samples > EYE_PROBE
                && c.samples < PLANNED_MASKS_FROM =>
        {
            MethodConfig::Exact(crate::methods::ExactConfig {
                probe: Some(EYE_PROBE),
                ..c
            })
        }
        _ => m,
    }
}

/// `render`, then the direct lighting of every pixel under `lighting`
/// (shading.rs) on the CPU whatever the backend, timed as `shading`.
/// `lighting` is checked against the call's light and meshes
/// (`Lighting::new`).
pub fn render_shaded(call: &EyeCall, lighting: &Lighting) -> Result<(Run<EyeImage>, Shaded)> {
    let mut runs = render_lights(call, &[(*call.light, lighting.clone())], &[])?;
    Ok(runs.remove(0))
}

/// Several lights seen through one camera: each light's call (`call` with
/// that light) run as `render` runs one, planned on its own (its own
/// method, maps focused on what it lights), the first light's first hits
/// shared by the others (`EyeCall::gbuffer`); then each shaded (shading.rs)
/// on the CPU whatever the backend, timed as `shading`, with one albedo
/// image: each mesh's material where `materials` has one (albedo.rs,
/// checked here, named `materials[k]`), else its `Lighting::albedo`. One
/// image per light, in order; the caller sums their shading. Refuses an
/// empty list or more than `MAX_LIGHTS` lights, naming `lights`.
pub fn render_lights(
    call: &EyeCall,
    lights: &[(Light, Lighting)],
    materials: &[Option<Material>],
) -> Result<Vec<(Run<EyeImage>, Shaded)>> {
    if lights.is_empty() || lights.len() > MAX_LIGHTS {
        return Err(Error::invalid(
            "lights",
            format!("must hold 1 to {MAX_LIGHTS} lights, got {}", lights.len()),
        ));
    }
    // One albedo image serves every light: their albedos must agree (the
    // bindings build them from one `albedo=`).
    if lights.iter().any(|(_, l)| l.albedo != lights[0].1.albedo) {
        return Err(Error::invalid(
            "albedo",
            "the lights of one call must share one albedo per mesh",
        ));
    }
    for (_, lighting) in lights {
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
    }
    if !materials.is_empty() && materials.len() != call.meshes.len() {
        return Err(Error::shape(
            "materials",
            format!(
                "{} materials for {} meshes",
                materials.len(),
                call.meshes.len()
            ),
        ));
    }
    for (k, (m, mesh)) in materials.iter().zip(call.meshes).enumerate() {
        if let Some(m) = m {
            m.check(&format!("materials[{k}]"), mesh)?;
        }
    }
    let cap = threads::resolve(call.threads)?;
    let target = match call.method {
        MethodConfig::Auto(a) => a.target.error.map(|e| e.0),
        _ => None,
    };
    let mut dim: Vec<Option<f64>> = vec![None; lights.len()];
    let mut runs: Vec<Run<EyeImage>> = Vec::with_capacity(lights.len());
    for (k, (light, _)) in lights.iter().enumerate() {
        if let (1, Some(e)) = (k, target) {
            let pairs: Vec<(&Light, [f64; 3])> =
                lights.iter().map(|(l, lt)| (l, lt.emission)).collect();
            let t0 = std::time::Instant::now();
            let g = &runs[0].output.gbuffer;
            let (found, _) = threads::run_capped(cap, || {
                Ok(crate::auto::dim_lights::unshadowed(&pairs, g, e))
            })?;
            for (j, share) in found {
                dim[j] = Some(share);
            }
            // Timed with the first light, whose first hits it reads.
            let seconds = t0.elapsed().as_secs_f64();
            runs[0].output.timings.push(("dim_lights", seconds));
        }
        if let (Some(share), Some(e)) = (dim[k], target) {
            runs.push(unshadowed_run(call.method, &runs[0], share, e));
            continue;
        }
        let shared = runs.first().map(|r| &r.output.gbuffer);
        let c = EyeCall {
            light,
            gbuffer: shared,
            ..*call
        };
        let one = render(&c)?;
        runs.push(one);
    }
    let t0 = std::time::Instant::now();
    let g = &runs[0].output.gbuffer;
    let (albedo, _) = threads::run_capped(cap, || {
        Ok(albedo_image(g, call.meshes, &lights[0].1.albedo, materials))
    })?;
    let albedo_seconds = t0.elapsed().as_secs_f64();
    let mut out = Vec::with_capacity(runs.len());
    for (mut run, (light, lighting)) in runs.into_iter().zip(lights) {
        let t0 = std::time::Instant::now();
        let img = &run.output;
        let (shaded, _) = threads::run_capped(cap, || {
            Ok(crate::eye::shading::shade(
                light,
                lighting.emission,
                &albedo,
                &img.gbuffer,
                &img.visibility,
                img.weighted.as_deref(),
            ))
        })?;
        let seconds =
            t0.elapsed().as_secs_f64() + if out.is_empty() { albedo_seconds } else { 0.0 };
        run.output.timings.push(("shading", seconds));
        out.push((run, shaded));
    }
    Ok(out)
}

/// A light of a call under `Auto(error=e)` too dim to shadow
/// (`auto::dim_lights`): visibility 1 on the first light's first hits, its
/// plan saying why.
fn unshadowed_run(
    method: MethodConfig,
    first: &Run<EyeImage>,
    share: f64,
    e: f64,
) -> Run<EyeImage> {
    let g = first.output.gbuffer.clone();
    let n = g.len();
    let why = format!(
        "not shadowed: with the call's other unshadowed lights it adds at most {share:.4} of the \
         unshadowed irradiance at any pixel, within the target {e}, so its shadow cannot move the \
         shaded image by more"
    );
    Run {
        output: EyeImage {
            gbuffer: g,
            visibility: vec![1.0; n],
            weighted: None,
            maps: None,
            light_space: None,
            timings: Timings::default(),
            estimate: None,
        },
        method,
        backend: first.backend,
        threads: first.threads,
        plan: Some(crate::auto::Plan {
            decisions: vec![crate::auto::Decision {
                name: "unshadowed",
                taken: true,
                why,
            }],
            hard: false,
            config: method,
            planned: None,
            slack: None,
        }),
    }
}

/// The error estimate, reported in a plan (`at`: "pixels" or "texels").
fn estimate_decision(e: &crate::error_estimate::ErrorEstimate, at: &str) -> crate::auto::Decision {
    crate::auto::Decision {
        name: "estimate",
        taken: true,
        why: format!(
            "measured error {:.4} (95% interval {:.4}-{:.4}) from exact rays ({} light samples) \
             at {} {at}, {} of them in shadow, in {:.1} ms",
            e.error,
            e.low,
            e.high,
            e.samples,
            e.traced,
            e.shadowed,
            e.seconds * 1e3
        ),
    }
}

/// What the eye view shades, reported in a plan: light-view texels only
/// where pixels need them (the maps fitted to the visible points, focus.rs),
/// or shadow rays from the visible pixels only.
fn focus_decision(image: &EyeImage) -> crate::auto::Decision {
    let pixels = image.gbuffer.hits().len();
    let why = match &image.maps {
        Some(m) => format!(
            "light-view maps {}x{} over the light-space bounds of the {pixels} visible points \
             only, at about one texel a pixel's footprint",
            m.grid.width, m.grid.height
        ),
        None => format!("shadow rays from the {pixels} pixels that see a surface only"),
    };
    crate::auto::Decision {
        name: "focus",
        taken: true,
        why,
    }
}
