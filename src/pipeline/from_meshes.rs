//! Meshes -> light-view maps -> visibility on the CPU: the receiver map,
//! then only what the method reads (occluder layers by depth peeling, or the
//! occluder triangles), then the method's shading.

use crate::error::Result;
use crate::geom::light::{is_point, MapGrid};
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::methods::{point_light, Input, Method, ShadowInputs};
use crate::raster::{rasterize, Prepared};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::frame::{frame_scene, FramedScene, Stopwatch, Timings};
use super::MapSettings;

/// What the mesh pipeline returns.
#[derive(Debug, Clone)]
pub struct ShadowResult {
    pub grid: MapGrid,
    pub occluder_grid: MapGrid,
    pub visibility: Vec<f32>,
    pub receiver: Vec<f32>,
    /// The occluder maps; None for methods that trace triangles instead.
    pub occluder_front: Option<Vec<f32>>,
    /// Peeled layers between front and back (passes >= 3), nearest first.
    pub occluder_middle: Vec<Vec<f32>>,
    pub occluder_back: Option<Vec<f32>>,
    pub timings: Timings,
    /// The light space the maps were computed in (the sun's depth origin
    /// and range are the scene's).
    pub light_space: LightSpace,
}

impl ShadowResult {
    /// The depth maps, computed in the kernels' depth unit `unit` (see
    /// units.rs), back in the user's units (a power of two, so exact), and
    /// for the sun from the kernels' depth to the orthographic one.
    pub(crate) fn in_user_units(mut self, unit: f64) -> ShadowResult {
        let space = self.light_space;
        let sun = matches!(space, LightSpace::Sun(_));
        if unit != 1.0 || sun {
            let maps = std::iter::once(&mut self.receiver)
                .chain(self.occluder_front.as_mut())
                .chain(self.occluder_middle.iter_mut())
                .chain(self.occluder_back.as_mut());
            for m in maps {
                m.par_iter_mut()
                    .for_each(|z| *z = space.user_depth(*z * unit as f32));
            }
        }
        self
    }

    /// The map's extent as the user reads it: tangent half-extents, or for
    /// the sun world half-extents.
    pub fn user_extent(&self) -> [f64; 2] {
        self.light_space.user_extent([self.grid.tx, self.grid.ty])
    }
}

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

/// Visibility of every receiver texel: the method's, or for a point light
/// (size 0) on the map methods the hard shadow they converge to.
pub(crate) fn shade_map(method: Method, inputs: &ShadowInputs) -> Vec<f32> {
    if is_point(inputs.light_size) && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_map(inputs)
    } else {
        method.implementation().visibility_map(inputs)
    }
}

/// Occluder triangles in light space, in f32 (relative to the light's center,
/// so precision does not depend on where the scene sits in the world).
pub fn light_space_triangles(verts: &[DVec3], faces: &[[u32; 3]]) -> Vec<[Vec3; 3]> {
    faces
        .par_iter()
        .map(|f| f.map(|i| verts[i as usize].as_vec3()))
        .collect()
}
