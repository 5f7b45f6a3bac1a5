//! Meshes -> light-view maps -> visibility, on either backend: the one
//! orchestrator of the light view. The scene is framed once (checks, light
//! space, grids: `crate::frame`), the backend's stages make the maps and
//! shade them (`crate::light_view`: the CPU's raster then shading, or the
//! GPU's one submission), and the result goes back to the user's units.

use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{frame_scene, MapSettings, ShadowResult};
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::light_view::{estimate, CpuLightView, LightMaps, LightViewStages};
use crate::timing::Stopwatch;

/// Soft shadow map from meshes on `backend`.
pub fn from_meshes(
    occluders: MeshRef,
    receivers: MeshRef,
    light: &LightSpace,
    s: &MapSettings,
    backend: Backend,
) -> Result<ShadowResult> {
    match backend {
        Backend::Cpu => from_meshes_with(&mut CpuLightView, occluders, receivers, light, s),
        #[cfg(feature = "gpu")]
        Backend::Gpu => from_meshes_with(
            &mut crate::gpu::light_view::GpuLightView::default(),
            occluders,
            receivers,
            light,
            s,
        ),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// Soft shadow map from meshes on `stages`' backend.
pub fn from_meshes_with<S: LightViewStages>(
    stages: &mut S,
    occluders: MeshRef,
    receivers: MeshRef,
    light: &LightSpace,
    s: &MapSettings,
) -> Result<ShadowResult> {
    stages.check_meshes(s)?;
    let mut sw = Stopwatch::new();
    let f = frame_scene(&occluders, &receivers, light, s, &mut sw)?;
    let LightMaps {
        visibility,
        receiver,
        front,
        middle,
        back,
    } = stages.meshes(&f, (occluders.faces, receivers.faces), s, &mut sw)?;
    // The estimate traces on the CPU whatever the backend, from the
    // receiver map the backend made.
    let estimate = s.estimate.map(|how| {
        let spent = sw.timings.iter().map(|t| t.1).sum();
        let e = estimate::of_meshes(
            &f,
            occluders.faces,
            (&receiver, &visibility),
            estimate::reference_samples(s.method),
            (how, spent),
        );
        sw.lap("estimate");
        e
    });
    Ok(ShadowResult {
        grid: f.grid,
        occluder_grid: f.occluder_grid,
        visibility,
        receiver,
        occluder_front: front,
        occluder_middle: middle,
        occluder_back: back,
        timings: stages.timings(sw.timings),
        light_space: *light,
        estimate,
    }
    .in_user_units(f.unit))
}
