//! Meshes -> light-view maps -> visibility on the CPU: the receiver map,
//! then only what the method reads (occluder layers by depth peeling, or the
//! occluder triangles), then the method's shading.

use crate::error::Result;
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::methods::{Input, ShadowInputs};
use crate::raster::{rasterize, Prepared};

use crate::frame::{frame_scene, light_space_triangles, FramedScene, MapSettings, ShadowResult};
use crate::methods::shade_map;
use crate::timing::Stopwatch;

/// Soft shadow map from meshes.
pub fn from_meshes(
    occluders: MeshRef,
    receivers: MeshRef,
    light: &LightSpace,
    s: &MapSettings,
) -> Result<ShadowResult> {
    let mut sw = Stopwatch::new();
    let FramedScene {
        occ_ls,
        rec_ls,
        grid,
        occluder_grid,
        near,
        unit,
        light_size,
    } = frame_scene(&occluders, &receivers, light, s, &mut sw)?;
    let receiver = rasterize(&grid, &rec_ls, receivers.faces, near, false).nearest;
    sw.lap("raster_receivers");
    // Only what the method reads: occluder maps for the map methods, light-space
    // triangles for the ray-traced one.
    let mut middle: Vec<Vec<f32>> = vec![];
    let triangles = s.method.reads_input(Input::OccluderTriangles).then(|| {
        let t = light_space_triangles(&occ_ls, occluders.faces);
        sw.lap("triangles");
        t
    });
    let occ = s.method.reads_input(Input::OccluderLayers).then(|| {
        // One set-up serves every layer: front and back in one traversal,
        // then one traversal per peeled layer (passes >= 3).
        let prepared = Prepared::new(&occluder_grid, &occ_ls, occluders.faces, near);
        let o = prepared.nearest_farthest(s.passes >= 2);
        for k in 0..s.passes.saturating_sub(2) as usize {
            let next = prepared.peel(if k == 0 { &o.nearest } else { &middle[k - 1] });
            middle.push(next);
        }
        sw.lap("raster_occluders");
        o
    });
    let mut layers: Vec<&[f32]> = vec![];
    if let Some(o) = &occ {
        layers.push(&o.nearest);
        layers.extend(middle.iter().map(|m| m.as_slice()));
        if let Some(back) = o.farthest.as_deref() {
            layers.push(back);
        }
    }
    let inputs = ShadowInputs {
        grid,
        occluder_grid,
        // The hard shadow map where a plan says every penumbra is under
        // half a texel (the point-light path of shade_map).
        light_size: if s.hard { [0.0; 2] } else { light_size },
        receiver: &receiver,
        occluder_layers: layers,
        occluder_triangles: triangles.as_deref(),
    };
    let visibility = shade_map(s.method, &inputs);
    sw.lap("shadow");
    let (occluder_front, occluder_back) = match occ {
        Some(o) => (Some(o.nearest), o.farthest),
        None => (None, None),
    };
    Ok(ShadowResult {
        grid,
        occluder_grid,
        visibility,
        receiver,
        occluder_front,
        occluder_middle: middle,
        occluder_back,
        timings: sw.timings,
        light_space: *light,
    }
    .in_user_units(unit))
}
