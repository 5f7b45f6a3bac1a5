//! Keeping a gather kernel's call (`ssm`, `bitmask`) within a bounded cost.
//!
//! The kernel's work is the receivers times the occluder texels each one's
//! light can reach (`methods::gather::work`). Where the light is wide (a
//! sun of tens of degrees and more) every receiver reaches the whole map,
//! and the fitted map, whose texels follow the pixels' footprint, makes the
//! work grow with the square of the pixels (a 179° sun: 0.08 s at 160x120,
//! 0.94 s at 320x240, 12.7 s at 640x480). So wide a light casts only
//! shadows as wide: a coarser map loses nothing a pixel can show. A fitted
//! map whose bound exceeds `PLANNED_VISITS` is made coarser until it does
//! not (the work falls with the texels, about as the square of the side).
//! A map size the user set is kept; what bounds every call, planned or
//! set, is the kernel's count of the visits it makes, stopped and refused
//! past `VISITS_PER_RECEIVER` a receiver (`methods::bounded`).

use super::call::EyeCall;
use super::maps::{kernel_point, EMPTY_POINT};
use crate::error::Result;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::gather::work::{visits_bound, PLANNED_VISITS};
use crate::methods::{LightPoint, MethodConfig};
use glam::DVec3;
use rayon::prelude::*;

/// Coarser grids tried at most (each one aims at the budget from the last
/// one's bound: one is nearly always enough).
const TRIES: usize = 4;

/// What the bound reads of the eye view's framing (`framing::Framed`).
pub struct Scene<'a> {
    /// The visible points in light space (not unit-scaled), the kernels'
    /// depth unit and the light's shape in it.
    pub pts_ls: &'a [DVec3],
    pub unit: f64,
    pub light_shape: LightShape,
    /// Every vertex in kernel light space, unit-scaled.
    pub verts: &'a [DVec3],
}

/// `planned` (the grid and config at `resolution`, fitted or given), or
/// where its work bound is over budget, the grid and config `at` gives for
/// a coarser resolution (the config derives its occluder grid from it, as
/// from the first); a size the user set is kept. With the resolution it
/// was planned at. `faces` are the occluders (indices into `f.verts`).
pub fn within_budget(
    call: &EyeCall,
    f: Scene,
    faces: &[[u32; 3]],
    resolution: (usize, usize),
    planned: (MapGrid, MethodConfig),
    at: impl Fn((usize, usize)) -> Result<(MapGrid, MethodConfig)>,
) -> Result<((MapGrid, MethodConfig), (usize, usize))> {
    let Some(visit_cost) = planned.1.kernel().visit_cost() else {
        return Ok((planned, resolution));
    };
    let Some(z_near) = nearest_occluder(&f, faces) else {
        return Ok((planned, resolution));
    };
    // The visible points as the kernels will read them (the biases, which
    // move them by a texel or so, left out).
    let inv_unit = 1.0 / f.unit;
    let points: Vec<LightPoint> = f
        .pts_ls
        .par_iter()
        .map(|q| {
            let q = *q * inv_unit;
            if q.z > 0.0 {
                kernel_point(q)
            } else {
                EMPTY_POINT
            }
        })
        .collect();
    let bound = |(grid, method): &(MapGrid, MethodConfig)| {
        let layers = method.passes() as usize;
        let cost = method.kernel().visit_cost().unwrap_or(visit_cost);
        cost * visits_bound(grid, f.light_shape, z_near, layers, &points)
    };
    let budget = PLANNED_VISITS;
    let mut plan = planned;
    let mut visits = bound(&plan);
    if visits <= budget {
        return Ok((plan, resolution));
    }
    // A map size the user set is kept: the kernel's meter refuses it, naming
    // the option, if its visits pass the limit (`methods::bounded`).
    if call.method.occluder_resolution().is_some() || call.map_resolution.is_some() {
        return Ok((plan, resolution));
    }
    let mut res = resolution;
    for _ in 0..TRIES {
        let scale = (budget / visits).sqrt().min(0.9);
        res = (
            ((res.0 as f64 * scale) as usize).max(1),
            ((res.1 as f64 * scale) as usize).max(1),
        );
        plan = at(res)?;
        visits = bound(&plan);
        if visits <= budget || res == (1, 1) {
            break;
        }
    }
    Ok((plan, res))
}

/// The nearest depth (kernel unit) of the occluders `faces` as the
/// rasterizer sees it: a triangle reaching the light's plane is clipped at
/// its near plane, whose depth is then the nearest. None when no occluder
/// lies in front of the light.
fn nearest_occluder(f: &Scene, faces: &[[u32; 3]]) -> Option<f64> {
    let z = faces
        .par_iter()
        .flat_map_iter(|t| t.iter().map(|&i| f.verts[i as usize].z))
        .reduce(|| f64::INFINITY, f64::min);
    if !(z < f64::INFINITY) {
        return None;
    }
    Some(z.max(crate::raster::near_plane(f.verts)))
}
