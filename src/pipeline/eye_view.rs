//! The eye view's one orchestrator: the same sequence of stages on the CPU
//! (`eye::CpuEye`) or the GPU (`gpu::eye::GpuEye`), so that both backends
//! frame, focus and shade alike and a new stage is added once.
//!
//! first hits (the G-buffer) -> `transform` (the visible points' light
//! space, `eye::framing`) -> per method: `exact`'s shadow rays from each
//! visible point; the map methods' casters, focused grid (`extent`),
//! occluder layers and shading at each pixel's point; ShadowMapping's own
//! stages (a hard shadow, any light). Visibility is 1 where a pixel sees no
//! surface.

use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::error_estimate::Draw;
use crate::eye::budget::traced_bytes;
use crate::eye::estimate::{self, REFERENCE_SAMPLES};
use crate::eye::framing::Framed;
use crate::eye::framing::{
    casting_faces, coarser, exact_samples, frame, light_triangles, map_grid, resolve_at_camera,
    traced_triangles,
};
use crate::eye::gbuffer::{GBuffer, SceneTriangles};
use crate::eye::prepared::Found;
use crate::eye::sphere_rays::sphere_bvh;
use crate::eye::{shadow_mapping, CpuEye, EyeCall, EyeImage, EyeStages};
use crate::geom::light::MapGrid;
use crate::geom::light_space::Light;
use crate::geom::sphere_light::SphereLight;
use crate::memory::{check_fits, map_bytes};
use crate::methods::config::MAX_SAMPLES;
use crate::methods::exact::Bvh;
use crate::methods::shadow_mapping::config::DepthBias;
use crate::methods::MethodConfig;
use crate::timing::Stopwatch;
use glam::Vec3;
use std::sync::Arc;
use std::time::Instant;

/// Seconds since `start`.
fn elapsed(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// What an `exact` run of a call built that another `exact` run of the same
/// call (other samples: `Auto`'s pilot and refinements, `auto/refine.rs`)
/// reads again: the first hits, the framing and the BVH of the triangles
/// the rays meet. A run that reuses them times none of those stages (the
/// run that built them did).
pub enum Traced {
    /// A planar light's or the sun's: the BVH in kernel light space.
    Planar {
        g: GBuffer,
        f: Box<Framed>,
        bvh: Bvh,
    },
    /// A sphere's (no framing): the BVH relative to its centre.
    Sphere { g: GBuffer, bvh: Bvh },
}

/// The call's triangles: kept by its preparation, or gathered and checked
/// now; and what the preparation found.
fn scene_of(call: &EyeCall) -> Result<(Arc<SceneTriangles>, Option<Found>)> {
    match call.prepared {
        Some(p) => {
            let found = p.find(call.meshes, call.light)?;
            Ok((found.scene.clone(), Some(found)))
        }
        None => Ok((Arc::new(SceneTriangles::new(call.meshes)?), None)),
    }
}

/// The first hits of `call`'s camera: another light's (`call.gbuffer`,
/// several lights in one call share them), or cast now on `stages`.
fn first_hits<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
    scene: &SceneTriangles,
) -> Result<GBuffer> {
    match call.gbuffer {
        Some(g) => Ok(g.clone()),
        None => stages.first_hits(call.camera, scene),
    }
}

/// Renders the visibility image of `call` on `backend`; returns the config
/// that ran (resolved for that backend).
pub fn render(call: &EyeCall, backend: Backend) -> Result<(EyeImage, MethodConfig)> {
    match backend {
        Backend::Cpu => render_with(&mut CpuEye, call, None),
        #[cfg(feature = "gpu")]
        Backend::Gpu => render_with(&mut crate::gpu::eye::GpuEye::default(), call, None),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// `render`, an `exact` run reusing `reuse` (taken from a run of the same
/// call) or leaving there what it built.
pub fn render_reusing(
    call: &EyeCall,
    backend: Backend,
    reuse: &mut Option<Traced>,
) -> Result<(EyeImage, MethodConfig)> {
    match backend {
        Backend::Cpu => render_with(&mut CpuEye, call, Some(reuse)),
        #[cfg(feature = "gpu")]
        Backend::Gpu => render_with(&mut crate::gpu::eye::GpuEye::default(), call, Some(reuse)),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// The stages of `call` in order, on `stages`' backend; an `exact` run
/// reuses what `reuse` holds, or leaves its own there.
pub fn render_with<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
    reuse: Option<&mut Option<Traced>>,
) -> Result<(EyeImage, MethodConfig)> {
    let start = Instant::now();
    let size = (call.camera.width, call.camera.height);
    if let MethodConfig::ShadowMapping(cfg) = call.method {
        // The depth map, and the second-nearest one for the midpoint bias.
        let (w, h) = cfg.resolution;
        let maps = 1 + usize::from(cfg.bias == DepthBias::Midpoint);
        check_fits(
            "resolution",
            &format!("a {w}x{h} shadow map"),
            map_bytes(w.saturating_mul(h), maps),
        )?;
        let method = resolve_at_camera(call, S::BACKEND)?;
        let mut sw = Stopwatch::new();
        let (scene, _) = scene_of(call)?;
        sw.lap("scene");
        let g = first_hits(stages, call, &scene)?;
        sw.lap("first_hits");
        let mut visibility = stages.shadow_mapping(call, &cfg, &scene, &g, &mut sw)?;
        if cfg.blur.is_some() {
            shadow_mapping::keep_unlit_dark(call, &g, &mut visibility);
        }
        // The estimate frames the scene for its exact rays: every
        // triangle can shadow (ShadowMapping does not pick casters).
        let estimate = if let Some(how) = call.estimate_error {
            let f = frame(call, &scene, &g)?;
            let at_hits: Vec<f32> = f.hits.iter().map(|&k| visibility[k]).collect();
            let tris = traced_triangles(&f, &scene);
            let e = estimate::estimate(
                &f,
                size,
                tris,
                &at_hits,
                REFERENCE_SAMPLES,
                (how, elapsed(start)),
            );
            sw.lap("estimate");
            Some(e)
        } else {
            None
        };
        let timings = stages.timings(sw.timings);
        let mut image = shadow_mapping::image(call, &scene, g, visibility, timings)?;
        image.estimate = estimate;
        return Ok((image, method));
    }
    if let Light::Sphere(s) = call.light {
        return render_sphere(stages, call, s, reuse, start);
    }
    stages.check(call)?;
    if call.method.kernel().traces() {
        return render_traced(stages, call, reuse, start);
    }
    let mut sw = Stopwatch::new();
    let (scene, _) = scene_of(call)?;
    sw.lap("scene");
    let g = first_hits(stages, call, &scene)?;
    sw.lap("first_hits");
    let mut f = frame(call, &scene, &g)?;
    sw.lap("transform");

    let mut visibility = vec![1f32; g.len()];
    let mut maps = None;
    let mut estimate = None;
    let mut weighted = None;
    let method;
    if !f.points.is_empty() {
        let casting = casting_faces(call, &scene, &f);
        let mut plan = map_grid(call, &g, &f, &casting, S::BACKEND)?;
        check_maps_fit(call, &plan.grid, &plan.method)?;
        sw.lap("extent");
        // The estimate's rays meet the casters only: the other triangles
        // cannot shadow a point that faces the light (casters.rs), and a
        // point facing away is 0 in both.
        let traced: Option<(Draw, Vec<[Vec3; 3]>)> = call.estimate_error.map(|how| {
            let t = casting
                .iter()
                .map(|t| t.map(|i| f.verts[i as usize].as_vec3()))
                .collect();
            (how, t)
        });
        let tris = light_triangles(&mut f, &casting);
        // A fitted plan whose kernel passed its visits' limit (the
        // prediction it was planned under fell short) runs again on a
        // coarser map (`framing::coarser`): so wide a light casts only
        // shadows as wide. A size the user set is refused, naming it
        // (`methods::bounded`).
        let shaded = loop {
            match stages.shade_maps(call, &f, &tris, plan.grid, &plan.method, &mut sw) {
                Err(e @ Error::TooCostly { .. }) => match coarser(call, &plan, S::BACKEND)? {
                    Some(p) => plan = p,
                    None => return Err(e),
                },
                r => break r?,
            }
        };
        method = plan.method;
        let v = shaded.visibility;
        maps = Some(shaded.maps);
        sw.lap("maps_out");
        if let Some((how, traced)) = traced {
            let e = estimate::estimate(
                &f,
                size,
                traced,
                &v,
                REFERENCE_SAMPLES,
                (how, elapsed(start)),
            );
            estimate = Some(e);
            sw.lap("estimate");
        }
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
        weighted = shaded.weighted.map(|vw| {
            let mut image = vec![1f32; g.len()];
            for (&k, v) in f.hits.iter().zip(vw) {
                image[k] = v;
            }
            image
        });
    } else {
        method = resolve_at_camera(call, S::BACKEND)?;
    }
    let timings = stages.timings(sw.timings);
    Ok((
        EyeImage {
            gbuffer: g,
            visibility,
            weighted,
            maps,
            light_space: Some(f.space),
            timings,
            estimate,
        },
        method,
    ))
}

/// `exact` under a sphere (`eye::sphere_rays`): the first hits, then
/// stratified rays over the cap each pixel sees, through one BVH of every
/// triangle (`EyeStages::trace_sphere`), and where asked the error estimate
/// against the same rays with four times the samples
/// (`estimate::estimate_sphere`), as `exact`'s under a planar light. A
/// sphere has no light space, so no framing; the first hits and the BVH
/// come from `reuse` where a run of the same call left them, and are left
/// there for the next.
fn render_sphere<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
    light: &SphereLight,
    mut reuse: Option<&mut Option<Traced>>,
    start: Instant,
) -> Result<(EyeImage, MethodConfig)> {
    let method = resolve_at_camera(call, S::BACKEND)?;
    let (samples, probe, _) = exact_samples(call, &method);
    let mut sw = Stopwatch::new();
    let (g, bvh) = match reuse.as_mut().and_then(|r| r.take()) {
        Some(Traced::Sphere { g, bvh }) => (g, bvh),
        _ => {
            check_traced_fit(call)?;
            let (scene, _) = scene_of(call)?;
            sw.lap("scene");
            let g = first_hits(stages, call, &scene)?;
            sw.lap("first_hits");
            let bvh = sphere_bvh(light, &scene.corners);
            crate::cancel::current().check()?;
            sw.lap("bvh");
            (g, bvh)
        }
    };
    let hits = g.hits();
    let v = stages.trace_sphere(&bvh, light, &g, &hits, samples, probe, &mut sw)?;
    crate::cancel::current().check()?;
    sw.lap("shadow");
    let estimate = call.estimate_error.map(|how| {
        let more = samples.saturating_mul(4).min(MAX_SAMPLES);
        let plain: Vec<f32> = v.iter().map(|[v, _]| *v).collect();
        let e = estimate::estimate_sphere(
            (&bvh, light),
            &g,
            &hits,
            &plain,
            more,
            (how, elapsed(start)),
        );
        sw.lap("estimate");
        e
    });
    crate::cancel::current().check()?;
    let mut visibility = vec![1f32; g.len()];
    let mut weighted = vec![1f32; g.len()];
    for (&k, [v, w]) in hits.iter().zip(v) {
        visibility[k] = v;
        weighted[k] = w;
    }
    let timings = stages.timings(sw.timings);
    let gbuffer = match reuse {
        Some(r) => {
            let kept = g.clone();
            *r = Some(Traced::Sphere { g, bvh });
            kept
        }
        None => g,
    };
    let image = EyeImage {
        gbuffer,
        visibility,
        weighted: Some(weighted),
        maps: None,
        light_space: None,
        timings,
        estimate,
    };
    Ok((image, method))
}

/// Refuses, before any map is allocated, occluder maps of `grid` that
/// `method` would keep more bytes of than are available: each layer and
/// the kernel's own maps of it (its 1/depth copy, corners, the
/// hierarchy's levels: `Method::kernel_maps_per_layer`, as the light view
/// counts them in `frame/light_view.rs`), and the copy of each layer the
/// image returns (an upper bound: at 4096², two layers, the process's peak
/// grew by 8.4 maps' bytes for `ssm`'s 10 counted here, and by 13.5 for
/// `bitmask`'s 34 with closed gaps). Named after the option
/// that set the size: the config's `occluder_resolution` where the user
/// gave one, else `map_resolution` (given, or fitted to the pixels).
fn check_maps_fit(call: &EyeCall, grid: &MapGrid, method: &MethodConfig) -> Result<()> {
    let layers = method.passes() as usize;
    let per_layer = 2 + method.kernel().kernel_maps_per_layer();
    check_fits(
        call.map_size_arg(),
        &format!(
            "{}x{} occluder maps ({layers} layers)",
            grid.width, grid.height
        ),
        map_bytes(grid.len(), per_layer * layers),
    )
}

/// Refuses, before anything is built, a traced call whose BVH, first hits
/// and rays' working memory do not fit, naming `meshes`.
fn check_traced_fit(call: &EyeCall) -> Result<()> {
    let triangles = call.meshes.iter().map(|m| m.faces.len()).sum();
    let vertices = call.meshes.iter().map(|m| m.vertices.len()).sum();
    let (w, h) = (call.camera.width, call.camera.height);
    check_fits(
        "meshes",
        &format!("{triangles} triangles traced at {w}x{h} pixels"),
        traced_bytes(triangles, vertices, w.saturating_mul(h)),
    )
}

/// `exact`: shadow rays from each visible point (`EyeStages::trace`) through
/// one BVH, which the error estimate traces too; the first hits, framing
/// and BVH from `reuse` where a run of the same call left them.
fn render_traced<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
    mut reuse: Option<&mut Option<Traced>>,
    start: Instant,
) -> Result<(EyeImage, MethodConfig)> {
    let size = (call.camera.width, call.camera.height);
    let method = resolve_at_camera(call, S::BACKEND)?;
    let (samples, probe, engine) = exact_samples(call, &method);
    let mut sw = Stopwatch::new();
    // Where this call's new tree's shape goes once it has been traced.
    let mut keep_for = None;
    let (g, f, mut bvh) = match reuse.as_mut().and_then(|r| r.take()) {
        Some(Traced::Planar { g, f, bvh }) => (g, *f, bvh),
        _ => {
            check_traced_fit(call)?;
            let (scene, found) = scene_of(call)?;
            sw.lap("scene");
            let g = first_hits(stages, call, &scene)?;
            sw.lap("first_hits");
            let f = frame(call, &scene, &g)?;
            sw.lap("transform");
            let tris = traced_triangles(&f, &scene);
            sw.lap("triangles");
            // A tree kept for this light's orientation is refitted to this
            // call's light space; otherwise one is built (and its shape
            // kept when the call has a preparation).
            let kept = found.as_ref().and_then(|x| x.tree.as_ref());
            let bvh = match kept.and_then(|t| t.refit(&tris)) {
                Some(bvh) => {
                    sw.lap("refit");
                    bvh
                }
                None => {
                    let bvh = Bvh::build(tris);
                    // A cancelled build is cut short: neither traced nor kept.
                    crate::cancel::current().check()?;
                    sw.lap("bvh");
                    keep_for = call.prepared.zip(found);
                    bvh
                }
            };
            (g, f, bvh)
        }
    };
    let (v, vw) = stages.trace(&f, &bvh, call.camera, (samples, probe, engine), &mut sw)?;
    sw.lap("shadow");
    // `exact` against itself with four times its samples, through the same
    // tree: its own sampling error.
    let estimate = call.estimate_error.map(|how| {
        let more = samples.saturating_mul(4).min(MAX_SAMPLES);
        let e = estimate::estimate_in(&f, size, &bvh, &v, more, (how, elapsed(start)));
        sw.lap("estimate");
        e
    });
    let mut visibility = vec![1f32; g.len()];
    for (&k, v) in f.hits.iter().zip(v) {
        visibility[k] = v;
    }
    let weighted = vw.map(|vw| {
        let mut image = vec![1f32; g.len()];
        for (&k, v) in f.hits.iter().zip(vw) {
            image[k] = v;
        }
        image
    });
    if let Some((p, found)) = keep_for {
        // The shape moves out of the tree when no later run reads it (a
        // copy took 30 ms on 2 000 000 triangles).
        let shape = match reuse {
            Some(_) => bvh.topology(),
            None => std::mem::replace(&mut bvh, Bvh::build(vec![])).into_topology(),
        };
        p.keep(&found, Arc::new(shape));
        sw.lap("keep");
    }
    let timings = stages.timings(sw.timings);
    let (gbuffer, light_space) = match reuse {
        Some(r) => {
            let kept = (g.clone(), f.space);
            *r = Some(Traced::Planar {
                g,
                f: Box::new(f),
                bvh,
            });
            kept
        }
        None => (g, f.space),
    };
    let image = EyeImage {
        gbuffer,
        visibility,
        weighted,
        maps: None,
        light_space: Some(light_space),
        timings,
        estimate,
    };
    Ok((image, method))
}
