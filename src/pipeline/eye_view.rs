//! The eye view's one orchestrator: the same sequence of stages on the CPU
//! (`eye::CpuEye`) or the GPU (`gpu::GpuEye`), so that both backends frame,
//! focus and shade alike and a new stage is added once.
//!
//! first hits (the G-buffer) -> `transform` (the visible points' light
//! space, `eye::framing`) -> per method: `exact`'s shadow rays from each
//! visible point; the map methods' casters, focused grid (`extent`),
//! occluder layers and shading at each pixel's point; ShadowMapping's own
//! stages (a hard shadow, any light). Visibility is 1 where a pixel sees no
//! surface.

use crate::backend::Backend;
use crate::error::Result;
use crate::eye::framing::{
    casting_faces, exact_samples, frame, light_triangles, map_grid, resolve_at_camera,
    traced_triangles,
};
use crate::eye::gbuffer::SceneTriangles;
use crate::eye::{shadow_mapping, CpuEye, EyeCall, EyeImage, EyeStages};
use crate::methods::MethodConfig;
use crate::timing::Stopwatch;

/// Renders the visibility image of `call` on `backend`; returns the config
/// that ran (resolved for that backend).
pub fn render(call: &EyeCall, backend: Backend) -> Result<(EyeImage, MethodConfig)> {
    match backend {
        Backend::Cpu => render_with(&mut CpuEye, call),
        #[cfg(feature = "gpu")]
        Backend::Gpu => render_with(&mut crate::gpu::GpuEye::default(), call),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// The stages of `call` in order, on `stages`' backend.
pub fn render_with<S: EyeStages>(
    stages: &mut S,
    call: &EyeCall,
) -> Result<(EyeImage, MethodConfig)> {
    if let MethodConfig::ShadowMapping(cfg) = call.method {
        let method = resolve_at_camera(call, S::BACKEND)?;
        let mut sw = Stopwatch::new();
        let scene = SceneTriangles::new(call.meshes)?;
        let g = stages.first_hits(call.camera, &scene)?;
        sw.lap("first_hits");
        let visibility = stages.shadow_mapping(call, &cfg, &scene, &g, &mut sw)?;
        let timings = stages.timings(sw.timings);
        let image = shadow_mapping::image(call, &scene, g, visibility, timings)?;
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
    let method;
    if call.method.kernel().traces() {
        method = resolve_at_camera(call, S::BACKEND)?;
        let samples = exact_samples(call, &method);
        let tris = traced_triangles(&f, &scene);
        sw.lap("triangles");
        let v = stages.trace(&f, tris, call.camera, samples, &mut sw)?;
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
        sw.lap("shadow");
    } else if !f.points.is_empty() {
        let casting = casting_faces(call, &scene, &f);
        let (grid, m) = map_grid(call, &g, &f, &casting, S::BACKEND)?;
        method = m;
        sw.lap("extent");
        let tris = light_triangles(&mut f, &casting);
        let (v, m) = stages.shade_maps(call, &f, &tris, grid, &method, &mut sw)?;
        for (&k, v) in f.hits.iter().zip(v) {
            visibility[k] = v;
        }
        maps = Some(m);
        sw.lap("maps_out");
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
        },
        method,
    ))
}
