//! Framing: a scene's meshes checked, moved to light space in the kernels'
//! depth unit (units.rs), and the map grids fitted to where its shadows can
//! fall (extent.rs). Both backends start from a framed scene.

use crate::error::{Error, Result};
use crate::geom::extent::fit_extent;
use crate::geom::light::MapGrid;
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::geom::units::{check_lateral, check_unit, depth_unit, light_size_in};
use crate::memory::{check_fits, map_bytes};
use crate::methods::Input;
use glam::DVec3;
use std::time::Instant;

use super::MapSettings;

/// Named stage durations in seconds, in the order they ran.
pub type Timings = Vec<(&'static str, f64)>;

pub(crate) struct Stopwatch {
    t: Instant,
    pub timings: Timings,
}

impl Stopwatch {
    pub fn new() -> Self {
        Stopwatch {
            t: Instant::now(),
            timings: Vec::new(),
        }
    }
    /// Records the time since the last lap as stage `name`.
    pub fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        self.timings.push((name, (now - self.t).as_secs_f64()));
        self.t = now;
    }
}

/// Clip distance for rasterization: a tiny fraction of the scene's depth range,
/// so that geometry touching the light's plane keeps finite 1/Z.
pub(crate) fn near_plane<'a>(verts: impl IntoIterator<Item = &'a DVec3>) -> f64 {
    let far = verts.into_iter().fold(0f64, |m, q| m.max(q.z.abs()));
    (far * 1e-9).max(f64::MIN_POSITIVE)
}

/// A scene moved to light space with its map grids fitted: what both
/// backends start from.
pub(crate) struct FramedScene {
    /// Light-space vertices in the kernels' depth unit (see units.rs).
    pub occ_ls: Vec<DVec3>,
    pub rec_ls: Vec<DVec3>,
    pub grid: MapGrid,
    pub occluder_grid: MapGrid,
    pub near: f64,
    /// The depth unit (a power of two): maps go back to the user's units
    /// by multiplying with it.
    pub unit: f64,
    /// The light's size in that unit.
    pub light_size: [f64; 2],
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
    let light_size = light_size_in("size", light.size(), unit)?;
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
        None => fit_extent(&occ_ls, &rec_ls, light_size)?,
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
        light_size,
    })
}

/// What a plan reads of a framed scene (`methods/plan.rs`): its
/// light-space depth ranges and bounds, the map's extent and the light's
/// size, for an output of `resolution`. One pass over the vertices; the
/// ratios the planner forms do not depend on the depth unit.
pub(crate) fn scene_stats(
    f: &FramedScene,
    resolution: (usize, usize),
) -> crate::methods::plan::SceneStats {
    let z_range = |v: &[DVec3]| {
        v.iter().fold((f64::INFINITY, 0f64), |(lo, hi), q| {
            (lo.min(q.z), hi.max(q.z))
        })
    };
    let (oz0, oz1) = z_range(&f.occ_ls);
    let (rz0, rz1) = z_range(&f.rec_ls);
    let bounds = f.occ_ls.iter().fold(
        [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, q| {
            let (x, y) = (q.x / q.z, q.y / q.z);
            [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)]
        },
    );
    let w = |z: f64| if z > 0.0 { 1.0 / z } else { f64::INFINITY };
    crate::methods::plan::SceneStats {
        resolution,
        extent: [f.grid.tx, f.grid.ty],
        light_size: f.light_size,
        occ_w_near: w(oz0),
        occ_w_far: w(oz1),
        rec_w_near: w(rz0.max(0.0)),
        rec_w_far: w(rz1),
        occ_bounds: bounds,
        // One depth to 1e-9 of it: a plane parallel to the light.
        occ_flat: oz1 - oz0 <= 1e-9 * oz1,
        occ_planar: on_one_plane(&f.occ_ls),
    }
}

/// Whether every point lies on one plane, to 1e-9 of the points' span:
/// the plane through the first point, the farthest from it, and the one
/// farthest from the line through both.
fn on_one_plane(v: &[DVec3]) -> bool {
    let Some(&a) = v.first() else {
        return true;
    };
    let farthest = |key: &dyn Fn(DVec3) -> f64| {
        v.iter()
            .copied()
            .max_by(|p, q| key(*p).total_cmp(&key(*q)))
            .unwrap_or(a)
    };
    let b = farthest(&|p| (p - a).length_squared());
    let span = (b - a).length();
    if span == 0.0 {
        return true;
    }
    let axis = (b - a) / span;
    let c = farthest(&|p| (p - a).cross(axis).length_squared());
    let n = (b - a).cross(c - a);
    if n.length() <= 1e-12 * span * span {
        // Collinear: a line lies on a plane.
        return true;
    }
    let n = n.normalize();
    v.iter().all(|p| n.dot(*p - a).abs() <= 1e-9 * span)
}

#[cfg(test)]
mod tests {
    use super::on_one_plane;
    use glam::DVec3;

    #[test]
    fn points_on_a_tilted_plane_are_planar_and_a_box_is_not() {
        let n = DVec3::new(0.3, 1.0, -0.2).normalize();
        let (u, v) = n.any_orthonormal_pair();
        let plane: Vec<DVec3> = (0..20)
            .map(|i| {
                DVec3::new(1.0, 2.0, 3.0) + u * (i as f64).sin() * 5.0 + v * (i as f64 * 0.7).cos()
            })
            .collect();
        assert!(on_one_plane(&plane));
        let mut off = plane.clone();
        off[7] += n * 1e-3;
        assert!(!on_one_plane(&off));
        let cube: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        assert!(!on_one_plane(&cube));
        // Fewer than three distinct points, or a line: planar.
        assert!(on_one_plane(&[DVec3::ONE, DVec3::ONE]));
        assert!(on_one_plane(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0]));
    }
}
