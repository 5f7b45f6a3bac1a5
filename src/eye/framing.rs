//! The eye view's framing, shared by the CPU stages and their GPU twins:
//! the visible points in the light's space (fitted to them for the sun),
//! the kernels' depth unit, the triangles in kernel light space, the
//! casters (`casters.rs`) and the occluder grid focused on what they can
//! shadow (`focus.rs`), and the config resolved at the camera or the grid.

use super::call::EyeCall;
use super::gbuffer::{GBuffer, SceneTriangles};
use super::{casters, focus, gather_budget, maps, tangent_plane};
use crate::backend::Backend;
use crate::error::Result;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::{sphere_has_no_space, Light, LightSpace};
use crate::geom::sun::SunSpace;
use crate::geom::units::{check_unit, depth_unit};
use crate::methods::config::CallContext;
use crate::methods::engine::Engine;
use crate::methods::MethodConfig;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::borrow::Cow;

/// What both backends derive from the G-buffer before shading: the visible
/// points, the light space fitted to them, the depth unit and every
/// triangle's corners in kernel light space.
pub struct Framed {
    /// Flat indices of the pixels that see a surface, and their world points
    /// and camera-facing normals.
    pub hits: Vec<usize>,
    pub points: Vec<[f64; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub space: LightSpace,
    /// The visible points in light space (not unit-scaled).
    pub pts_ls: Vec<DVec3>,
    /// The kernels' depth unit, and the light's shape in it.
    pub unit: f64,
    pub light_shape: LightShape,
    /// Every vertex in kernel light space, unit-scaled (the faces into them
    /// are `SceneTriangles::faces`).
    pub verts: Vec<DVec3>,
}

impl Framed {
    /// The visible points biased and bounded for the map kernels on `grid`
    /// (`maps::shading_points`), with their tangent planes where `planes`.
    pub fn shading_points(
        &self,
        grid: &MapGrid,
        bias: &maps::Bias,
        planes: bool,
    ) -> maps::ShadingPoints {
        maps::shading_points(
            &self.space,
            self.unit,
            self.light_shape,
            grid,
            &self.points,
            &self.pts_ls,
            &self.normals,
            bias,
            planes,
        )
    }
}

/// The light space, depth unit and light-space triangles of an image whose
/// G-buffer is `g`.
pub fn frame(call: &EyeCall, scene: &SceneTriangles, g: &GBuffer) -> Result<Framed> {
    let hits = g.hits();
    let points: Vec<[f64; 3]> = hits.par_iter().map(|&k| g.position[k]).collect();
    let normals: Vec<[f32; 3]> = hits.par_iter().map(|&k| g.normal[k]).collect();
    let space = match call.light {
        Light::Area(l) => LightSpace::Area(*l),
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
        Light::Sphere(_) => return Err(sphere_has_no_space()),
    };
    // Kernel light space, in the depth unit of the visible points.
    let pts_ls: Vec<DVec3> = points
        .par_iter()
        .map(|p| space.to_light(DVec3::from_array(*p)))
        .collect();
    let unit = depth_unit(pts_ls.par_iter().map(|q| q.z).reduce(|| 0.0, f64::max));
    check_unit("meshes", unit)?;
    let light_shape = space.shape().in_unit("size", unit)?;
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
        light_shape,
        verts,
    })
}

/// The most points the median pixel footprint is taken over (focus.rs).
const FOOTPRINT_SAMPLES: usize = 1 << 14;

/// The config of a call that reads no maps (`exact`, or no visible point),
/// resolved for `backend` at the camera's resolution.
pub fn resolve_at_camera(call: &EyeCall, backend: Backend) -> Result<MethodConfig> {
    call.method.resolve(&CallContext {
        backend,
        resolution: (call.camera.width, call.camera.height),
        depth_layers: None,
        eye: true,
    })
}

/// Light samples per pixel of `exact`, and of its probe, and the engine
/// that decides them: a hard light needs one ray (every sample would be the
/// same) and no probe.
pub fn exact_samples(call: &EyeCall, method: &MethodConfig) -> (u32, Option<u32>, Engine) {
    match method.kernel().rays() {
        Some(rays) if !call.light.is_hard() => rays,
        _ => (1, None, Engine::Rays),
    }
}

/// The triangles `exact` traces: the corners in f32.
pub fn traced_triangles(f: &Framed, scene: &SceneTriangles) -> Vec<[Vec3; 3]> {
    scene
        .faces
        .par_iter()
        .map(|t| t.map(|i| f.verts[i as usize].as_vec3()))
        .collect()
}

/// The faces that can shadow a visible point (`casters.rs`): the map
/// methods' occluders. Points facing away from the whole light are not
/// asked about: their visibility is 0 whatever shadows them
/// (`maps::shading_points`, the tangent-plane bound), and a box floor's
/// sides facing away from the light would otherwise keep its top face a
/// caster. A kernel that reads every face keeps them all
/// (`Kernel::READS_EVERY_FACE`: the smoothies).
pub fn casting_faces<'s>(
    call: &EyeCall,
    scene: &'s SceneTriangles,
    f: &Framed,
) -> Cow<'s, [[u32; 3]]> {
    if call.method.kernel().reads_every_face() {
        return Cow::Borrowed(&scene.faces);
    }
    let facing: Vec<[f64; 3]> = f
        .points
        .par_iter()
        .zip(&f.normals)
        .filter(|(p, n)| {
            let n = glam::Vec3::from_array(**n).as_dvec3();
            tangent_plane::front_of(&f.space, f.unit, f.light_shape, DVec3::from_array(**p), n)
                > 0.0
        })
        .map(|(p, _)| *p)
        .collect();
    let casts = casters::casting_triangles(scene, call.light, &facing);
    scene
        .faces
        .iter()
        .zip(&casts)
        .filter(|(_, &c)| c)
        .map(|(t, _)| *t)
        .collect::<Vec<_>>()
        .into()
}

/// The map methods' plan: their occluder grid, the config resolved for a
/// backend at a resolution, and that resolution.
pub struct MapPlan {
    pub grid: MapGrid,
    pub method: MethodConfig,
    pub resolution: (usize, usize),
}

/// The map methods' occluder grid (focused on what the occluders `faces`
/// can shadow of the visible points, sized from their footprint unless the
/// call sets it) and the config resolved for `backend` at that resolution.
/// `f` has visible points.
pub fn map_grid(
    call: &EyeCall,
    g: &GBuffer,
    f: &Framed,
    faces: &[[u32; 3]],
    backend: Backend,
) -> Result<MapPlan> {
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
        Some(v) => focus::focused_extent(&occluders, v, f.light_shape)?,
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
                    LightSpace::Area(_) => world / q.z,
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
    let (grid, method) = grid_at(call, resolution, extent, backend)?;
    let scene = gather_budget::Scene {
        pts_ls: &f.pts_ls,
        unit: f.unit,
        light_shape: f.light_shape,
        verts: &f.verts,
    };
    let ((grid, method), resolution) =
        gather_budget::within_budget(call, scene, faces, resolution, (grid, method), |r| {
            grid_at(call, r, extent, backend)
        })?;
    Ok(MapPlan {
        grid,
        method,
        resolution,
    })
}

/// The side of a retried fitted plan, relative to the stopped one's.
const RETRY_SCALE: f64 = 0.35;

/// `plan` at 0.35 of its resolution a side (an eighth of the texels), over
/// the same extent: the fitted plan whose kernel passed its visits' limit
/// (`methods::bounded`) runs again on it (its visits fall about as the
/// texels, so one retry covers an overrun up to about 8x, where halving took
/// two on the closed room with 1 024 samples). A fixed factor, not
/// one from an estimate of the overrun: how many groups a stopped kernel
/// shaded depends on the threads, and the map, hence the result, must
/// not. None
/// where the call set the map size (the refusal stands) or the plan is
/// already 1x1.
pub fn coarser(call: &EyeCall, plan: &MapPlan, backend: Backend) -> Result<Option<MapPlan>> {
    let (w, h) = plan.resolution;
    if call.map_resolution.is_some() || call.method.occluder_resolution().is_some() || w * h <= 1 {
        return Ok(None);
    }
    let side = |n: usize| ((n as f64 * RETRY_SCALE) as usize).max(1);
    let resolution = (side(w), side(h));
    let (grid, method) = grid_at(call, resolution, [plan.grid.tx, plan.grid.ty], backend)?;
    Ok(Some(MapPlan {
        grid,
        method,
        resolution,
    }))
}

/// The config resolved for `backend` at `resolution` and its occluder grid
/// over `extent`: the eye view has occluder maps only, at the resolved
/// config's occluder resolution (`resolution` unless the config sets one;
/// "auto"'s rule takes a quarter of it).
fn grid_at(
    call: &EyeCall,
    resolution: (usize, usize),
    extent: [f64; 2],
    backend: Backend,
) -> Result<(MapGrid, MethodConfig)> {
    let method = call.method.resolve(&CallContext {
        backend,
        resolution,
        depth_layers: None,
        eye: true,
    })?;
    let (w, h) = method.occluder_resolution().unwrap_or(resolution);
    Ok((MapGrid::new(w, h, extent)?, method))
}

/// The occluders `faces` as one indexed mesh in kernel light space (the map
/// methods' occluders), its vertices taken out of `f`.
pub fn light_triangles<'s>(f: &mut Framed, faces: &'s [[u32; 3]]) -> maps::LightTriangles<'s> {
    maps::LightTriangles {
        verts: std::mem::take(&mut f.verts),
        faces,
    }
}
