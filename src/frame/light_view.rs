//! Framing: a scene's meshes checked, moved to light space in the kernels'
//! depth unit (units.rs), and the map grids fitted to where its shadows can
//! fall (extent.rs). Both backends start from a framed scene.

use crate::error::{Error, Result};
use crate::error_estimate::{Draw, ErrorEstimate};
use crate::geom::extent::fit_extent;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::geom::units::{check_lateral, check_unit, depth_unit};
use crate::memory::{check_fits, map_bytes};
use crate::methods::{Input, Method, MethodConfig};
use crate::raster::near_plane;
use crate::timing::Stopwatch;
use crate::timing::Timings;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// A scene moved to light space with its map grids fitted: what both
/// backends start from.
pub struct FramedScene {
    /// Light-space vertices in the kernels' depth unit (see units.rs).
    pub occ_ls: Vec<DVec3>,
    pub rec_ls: Vec<DVec3>,
    pub grid: MapGrid,
    pub occluder_grid: MapGrid,
    pub near: f64,
    /// The depth unit (a power of two): maps go back to the user's units
    /// by multiplying with it.
    pub unit: f64,
    /// The light's shape in that unit.
    pub light_shape: LightShape,
}

/// Checks the input, moves the meshes to light space and fits the grids
/// (stages "transform" and "extent").
pub(crate) fn frame_scene(
    occluders: &MeshRef,
    receivers: &MeshRef,
    light: &LightSpace,
    s: &MapSettings,
    sw: &mut Stopwatch,
) -> Result<FramedScene> {
    // Passes were checked when the config was built (methods/config.rs).
    if occluders.is_empty() {
        return Err(Error::invalid(
            "occluders",
            "the scene has no occluder triangles",
        ));
    }
    if receivers.is_empty() {
        return Err(Error::invalid(
            "receivers",
            "the scene has no receiver triangles",
        ));
    }
    // Refuse an absurd resolution before touching the meshes.
    MapGrid::new(s.width, s.height, s.extent.unwrap_or([1.0, 1.0]))?;
    let (ow, oh) = s.occluder_resolution.unwrap_or((s.width, s.height));
    MapGrid::new(ow, oh, s.extent.unwrap_or([1.0, 1.0]))
        .map_err(|e| Error::invalid("occluder_resolution", e.to_string()))?;
    // Receiver and visibility maps; each occluder layer and what the
    // kernel keeps of it (its 1/depth copy, corners).
    let layers = if s.method.reads_input(Input::OccluderLayers) {
        s.passes as usize
    } else {
        0
    };
    check_fits(
        "resolution",
        &format!(
            "{}x{} with {}x{} occluder maps and {} layers",
            s.width, s.height, ow, oh, layers
        ),
        map_bytes(s.width * s.height, 2)
            + map_bytes(ow * oh, (1 + s.method.kernel_maps_per_layer()) * layers),
    )?;
    occluders.validate("occluders")?;
    receivers.validate("receivers")?;

    let mut occ_ls = occluders.to_light_space(light);
    let mut rec_ls = receivers.to_light_space(light);
    // Light space in the kernels' depth unit (see units.rs); maps go back to
    // the user's units at the end.
    let unit = depth_unit(rec_ls.iter().fold(0f64, |m, q| m.max(q.z)));
    check_unit("receivers", unit)?;
    let light_shape = light.shape().in_unit("size", unit)?;
    if unit != 1.0 {
        for q in occ_ls.iter_mut().chain(rec_ls.iter_mut()) {
            *q /= unit;
        }
    }
    check_lateral("occluders", &occ_ls, unit)?;
    check_lateral("receivers", &rec_ls, unit)?;
    sw.lap("transform");
    let extent = match s.extent {
        Some(e) => e,
        None => fit_extent(&occ_ls, &rec_ls, light_shape)?,
    };
    let grid = MapGrid::new(s.width, s.height, extent)?;
    let occluder_grid = MapGrid::new(ow, oh, extent)?;
    sw.lap("extent");
    let near = near_plane(occ_ls.iter().chain(&rec_ls));
    Ok(FramedScene {
        occ_ls,
        rec_ls,
        grid,
        occluder_grid,
        near,
        unit,
        light_shape,
    })
}

/// Settings of the mesh pipeline.
#[derive(Debug, Clone, Copy)]
pub struct MapSettings {
    pub width: usize,
    pub height: usize,
    /// Tangent half-extents, or `None` to fit them (see `extent.rs`).
    pub extent: Option<[f64; 2]>,
    /// Resolution of the occluder maps (same extent); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
    pub passes: u32,
    pub method: Method,
    /// Shade the map methods' layers as for a point light (hard shadows),
    /// whatever the light's size: what a plan decides where every penumbra
    /// is under half a texel (`auto/plan.rs`).
    pub hard: bool,
    /// Estimate the result's error from exact rays at texels drawn as it
    /// says (`crate::light_view::estimate`); None: no estimate.
    pub estimate: Option<Draw>,
}

impl MapSettings {
    /// The settings of a resolved config (see `MethodConfig::resolve`).
    pub fn new(
        width: usize,
        height: usize,
        extent: Option<[f64; 2]>,
        method: &MethodConfig,
    ) -> MapSettings {
        MapSettings {
            width,
            height,
            extent,
            occluder_resolution: method.occluder_resolution(),
            passes: method.passes(),
            method: method.kernel(),
            hard: false,
            estimate: None,
        }
    }
}

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
    /// The error estimate, when the settings asked for one.
    pub estimate: Option<ErrorEstimate>,
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

/// Occluder triangles in light space, in f32 (relative to the light's center,
/// so precision does not depend on where the scene sits in the world).
pub fn light_space_triangles(verts: &[DVec3], faces: &[[u32; 3]]) -> Vec<[Vec3; 3]> {
    faces
        .par_iter()
        .map(|f| f.map(|i| verts[i as usize].as_vec3()))
        .collect()
}
