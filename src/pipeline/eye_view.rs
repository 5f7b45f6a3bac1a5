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
use crate::error::Result;
use crate::error_estimate::Draw;
use crate::eye::estimate::{self, REFERENCE_SAMPLES};
use crate::eye::framing::{
    casting_faces, exact_samples, frame, light_triangles, map_grid, resolve_at_camera,
    traced_triangles,
};
use crate::eye::gbuffer::SceneTriangles;
use crate::eye::{shadow_mapping, CpuEye, EyeCall, EyeImage, EyeStages};
use crate::methods::config::MAX_SAMPLES;
use crate::methods::MethodConfig;
use crate::timing::Stopwatch;
use glam::Vec3;
use std::time::Instant;

/// Seconds since `start`.
fn elapsed(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// Renders the visibility image of `call` on `backend`; returns the config
/// that ran (resolved for that backend).
pub fn render(call: &EyeCall, backend: Backend) -> Result<(EyeImage, MethodConfig)> {
    match backend {
        Backend::Cpu => render_with(&mut CpuEye, call),
        #[cfg(feature = "gpu")]
        Backend::Gpu => render_with(&mut crate::gpu::eye::GpuEye::default(), call),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// The stages of `call` in order, on `stages`' backend.
pub fn render_with<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
) -> Result<(EyeImage, MethodConfig)> {
    let start = Instant::now();
    let size = (call.camera.width, call.camera.height);
    if let MethodConfig::ShadowMapping(cfg) = call.method {
        let method = resolve_at_camera(call, S::BACKEND)?;
        let mut sw = Stopwatch::new();
        let scene = SceneTriangles::new(call.meshes)?;
        let g = stages.first_hits(call.camera, &scene)?;
        sw.lap("first_hits");
        let visibility = stages.shadow_mapping(call, &cfg, &scene, &g, &mut sw)?;
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
    stages.check(call)?;
    let mut sw = Stopwatch::new();
    let scene = SceneTriangles::new(call.meshes)?;
    let g = stages.first_hits(call.camera, &scene)?;
    sw.lap("first_hits");
    let mut f = frame(call, &scene, &g)?;
    sw.lap("transform");

    let mut visibility = vec![1f32; g.len()];
    let mut maps = None;
    let mut estimate = None;
    let method;
    if call.method.kernel().traces() {
        method = resolve_at_camera(call, S::BACKEND)?;
        let samples = exact_samples(call, &method);
        let tris = traced_triangles(&f, &scene);
        sw.lap("triangles");
        let again = call.estimate_error.map(|how| (how, tris.clone()));
        let v = stages.trace(&f, tris, call.camera, samples, &mut sw)?;
        sw.lap("shadow");
        // `exact` against itself with four times its samples: its own
        // sampling error.
        if let Some((how, tris)) = again {
            let more = samples.saturating_mul(4).min(MAX_SAMPLES);
            estimate = Some(estimate::estimate(
                &f,
                size,
                tris,
                &v,
                more,
                (how, elapsed(start)),
            ));
            sw.lap("estimate");
        }
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
    } else if !f.points.is_empty() {
        let casting = casting_faces(call, &scene, &f);
        let (grid, m) = map_grid(call, &g, &f, &casting, S::BACKEND)?;
        method = m;
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
        let (v, m) = stages.shade_maps(call, &f, &tris, grid, &method, &mut sw)?;
        maps = Some(m);
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
    } else {
        method = resolve_at_camera(call, S::BACKEND)?;
    }
    let timings = stages.timings(sw.timings);
    Ok((
        EyeImage {
            gbuffer: g,
            visibility,
            maps,
            light_space: f.space,
            timings,
            estimate,
        },
        method,
    ))
}
