//! The end-to-end pipelines: meshes -> light-view maps -> visibility, and
//! depth maps -> visibility. Timings are kept per stage.

use crate::error::{Error, Result};
use crate::extent::fit_extent;
use crate::light::{check_light_size, is_point, MapGrid, RectLight};
use crate::memory::{check_fits, map_bytes};
use crate::mesh::MeshRef;
use crate::methods::{LightPoint, Method, ShadowInputs};
use crate::point_light;
use crate::raster::{rasterize, Prepared};
use crate::units::{check_lateral, check_unit, depth_unit, farthest, light_size_in, scaled_map};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::borrow::Cow;
use std::time::Instant;

/// The most occluder depth layers we peel.
pub const MAX_PASSES: u32 = 8;

/// How many occluder depth layers are taken: 1, the front; 2, front and back
/// (§3.5); more, front, the next layers by depth peeling, and back.
pub fn check_passes(passes: u32) -> Result<u32> {
    if (1..=MAX_PASSES).contains(&passes) {
        Ok(passes)
    } else {
        Err(Error::invalid(
            "passes",
            format!(
                "must be 1 (front layer), 2 (front and back) or up to {MAX_PASSES} (front, peeled layers, back), got {passes}"
            ),
        ))
    }
}

/// Named stage durations in seconds, in the order they ran.
pub type Timings = Vec<(&'static str, f64)>;

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
}

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
fn near_plane(occ: &[DVec3], rec: &[DVec3]) -> f64 {
    let far = occ.iter().chain(rec).fold(0f64, |m, q| m.max(q.z.abs()));
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

impl ShadowResult {
    /// The depth maps, computed in the kernels' depth unit `unit` (see
    /// units.rs), back in the user's units: a power of two, so exact.
    pub(crate) fn in_user_units(mut self, unit: f64) -> ShadowResult {
        if unit != 1.0 {
            let maps = std::iter::once(&mut self.receiver)
                .chain(self.occluder_front.as_mut())
                .chain(self.occluder_middle.iter_mut())
                .chain(self.occluder_back.as_mut());
            for m in maps {
                m.par_iter_mut().for_each(|z| *z *= unit as f32);
            }
        }
        self
    }
}

/// Checks the input, moves the meshes to light space and fits the grids
/// (stages "transform" and "extent").
pub(crate) fn frame_scene(
    occluders: &MeshRef,
    receivers: &MeshRef,
    light: &RectLight,
    s: &MapSettings,
    sw: &mut Stopwatch,
) -> Result<FramedScene> {
    check_passes(s.passes)?;
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
    // Receiver and visibility maps; each occluder layer and the kernels'
    // 1/depth copy of it.
    let layers = if s.method.traces_triangles() {
        0
    } else {
        s.passes as usize
    };
    check_fits(
        "resolution",
        &format!(
            "{}x{} with {}x{} occluder maps and {} layers",
            s.width, s.height, ow, oh, layers
        ),
        map_bytes(s.width * s.height, 2) + map_bytes(ow * oh, 2 * layers),
    )?;
    occluders.validate("occluders")?;
    receivers.validate("receivers")?;

    let mut occ_ls = occluders.to_light_space(light);
    let mut rec_ls = receivers.to_light_space(light);
    // Light space in the kernels' depth unit (see units.rs); maps go back to
    // the user's units at the end.
    let unit = depth_unit(rec_ls.iter().fold(0f64, |m, q| m.max(q.z)));
    check_unit("receivers", unit)?;
    let light_size = light_size_in("size", light.size, unit)?;
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
    let near = near_plane(&occ_ls, &rec_ls);
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

/// Soft shadow map from meshes.
pub fn from_meshes(
    occluders: MeshRef,
    receivers: MeshRef,
    light: &RectLight,
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
    let (occ, triangles) = if s.method.traces_triangles() {
        let t = light_space_triangles(&occ_ls, occluders.faces);
        sw.lap("triangles");
        (None, Some(t))
    } else {
        // One set-up serves every layer: front and back in one traversal,
        // then one traversal per peeled layer (passes >= 3).
        let prepared = Prepared::new(&occluder_grid, &occ_ls, occluders.faces, near);
        let o = prepared.nearest_farthest(s.passes >= 2);
        for k in 0..s.passes.saturating_sub(2) as usize {
            let next = prepared.peel(if k == 0 { &o.nearest } else { &middle[k - 1] });
            middle.push(next);
        }
        sw.lap("raster_occluders");
        (Some(o), None)
    };
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
        light_size,
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
    }
    .in_user_units(unit))
}

/// Visibility of every receiver texel: the method's, or for a point light
/// (size 0) on the map methods the hard shadow they converge to.
fn shade_map(method: Method, inputs: &ShadowInputs) -> Vec<f32> {
    if is_point(inputs.light_size) && !method.traces_triangles() {
        point_light::visibility_map(inputs)
    } else {
        method.implementation().visibility_map(inputs)
    }
}

/// Visibility at receiver points, as `shade_map`.
fn shade_points(method: Method, inputs: &ShadowInputs, pts: &[LightPoint]) -> Vec<f32> {
    if is_point(inputs.light_size) && !method.traces_triangles() {
        point_light::visibility_points(inputs, pts)
    } else {
        method.implementation().visibility_points(inputs, pts)
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

/// Checks a user depth map: finite and > 0, or +inf for "nothing here".
pub fn check_depth(arg: &str, depth: &[f32]) -> Result<()> {
    if let Some(k) = depth.par_iter().position_any(|&z| !(z > 0.0)) {
        return Err(Error::invalid(
            arg,
            format!(
                "depths must be > 0 (planar distance from the light) or +inf where empty; \
                 texel {k} holds {}",
                depth[k]
            ),
        ));
    }
    Ok(())
}

/// Checks the inputs of `from_depth` (both backends): the light size, a
/// method that reads maps, each map's size and depths. Returns the light size.
pub(crate) fn check_depth_inputs(
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_size: [f64; 2],
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<[f64; 2]> {
    let light_size = check_light_size("light_size", light_size)?;
    if method.traces_triangles() {
        return Err(Error::invalid(
            "method",
            "traces the occluder triangles, which depth maps do not have; use soft_shadow_map with meshes",
        ));
    }
    for (arg, d, g) in [
        ("occluder_depth", Some(front), occluder_grid),
        ("occluder_depth_back", back, occluder_grid),
        ("receiver_depth", Some(receiver), grid),
    ] {
        if let Some(d) = d {
            if d.len() != g.len() {
                return Err(Error::shape(
                    arg,
                    format!("has {} texels, expected {}x{}", d.len(), g.height, g.width),
                ));
            }
            check_depth(arg, d)?;
        }
    }
    Ok(light_size)
}

/// The user's depth maps and light size in the kernels' depth unit (see
/// units.rs), shared by both backends; the maps are copied only when the unit
/// is not 1.
pub(crate) struct DepthInUnit<'a> {
    pub light_size: [f64; 2],
    pub front: Cow<'a, [f32]>,
    pub back: Option<Cow<'a, [f32]>>,
    pub receiver: Cow<'a, [f32]>,
}

impl<'a> DepthInUnit<'a> {
    pub(crate) fn new(
        unit: f64,
        light_size: [f64; 2],
        front: &'a [f32],
        back: Option<&'a [f32]>,
        receiver: &'a [f32],
    ) -> Result<DepthInUnit<'a>> {
        Ok(DepthInUnit {
            light_size: light_size_in("light_size", light_size, unit)?,
            front: scaled_map(front, unit),
            back: back.map(|b| scaled_map(b, unit)),
            receiver: scaled_map(receiver, unit),
        })
    }
}

/// Soft shadow map from depth maps the user rendered.
pub fn from_depth(
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_size: [f64; 2],
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<(Vec<f32>, Timings)> {
    let light_size = check_depth_inputs(
        grid,
        occluder_grid,
        light_size,
        front,
        back,
        receiver,
        method,
    )?;
    let mut sw = Stopwatch::new();
    // The kernels' depth unit (see units.rs): copies only far from 1.
    let unit = depth_unit(farthest(receiver));
    // Visibility, the kernels' 1/depth layers, and the copies in that unit.
    let copies = if unit == 1.0 { 0 } else { 1 };
    let layers = 1 + back.is_some() as usize;
    check_fits(
        "receiver_depth",
        &format!("{}x{} maps", grid.width, grid.height),
        map_bytes(grid.len(), 1 + copies) + map_bytes(occluder_grid.len(), layers * (1 + copies)),
    )?;
    let d = DepthInUnit::new(unit, light_size, front, back, receiver)?;
    let mut layers: Vec<&[f32]> = vec![&d.front];
    if let Some(b) = &d.back {
        layers.push(b);
    }
    let inputs = ShadowInputs {
        grid: *grid,
        occluder_grid: *occluder_grid,
        light_size: d.light_size,
        receiver: &d.receiver,
        occluder_layers: layers,
        occluder_triangles: None,
    };
    let v = shade_map(method, &inputs);
    sw.lap("shadow");
    Ok((v, sw.timings))
}

/// What a method reads of the occluders when shading points.
#[derive(Debug, Clone)]
pub enum OccluderSource<'a> {
    /// The occluder maps of a shadow map (front, and back with two passes) on
    /// their grid.
    Maps {
        grid: MapGrid,
        /// Front first, back last.
        layers: Vec<&'a [f32]>,
    },
    /// The occluder triangles (world space).
    Mesh(MeshRef<'a>),
}

/// Visibility at world points, from the occluders of a shadow map.
/// Returns the visibility and whether each point fell inside the map (points
/// outside it or at/behind the light's plane get visibility 1 and `false`).
pub fn sample_points(
    grid: &MapGrid,
    light: &RectLight,
    occluders: OccluderSource,
    points: &[[f64; 3]],
    method: Method,
) -> Result<(Vec<f32>, Vec<bool>)> {
    if let Some(k) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::invalid(
            "points",
            format!("point {k} is not finite: {:?}", points[k]),
        ));
    }
    let ls_points: Vec<DVec3> = points
        .par_iter()
        .map(|p| light.to_light(DVec3::from_array(*p)))
        .collect();
    let inside_map =
        |q: &DVec3| q.z > 0.0 && (q.x / q.z).abs() <= grid.tx && (q.y / q.z).abs() <= grid.ty;
    // The kernels' depth unit (see units.rs), from the points inside the map.
    let unit = depth_unit(
        ls_points
            .iter()
            .filter(|q| inside_map(q))
            .fold(0f64, |m, q| m.max(q.z)),
    );
    check_unit("points", unit)?;
    let light_size = light_size_in("size", light.size, unit)?;
    let (ls, inside): (Vec<LightPoint>, Vec<bool>) = ls_points
        .par_iter()
        .map(|q| {
            if !inside_map(q) {
                // Outside the map, or at or behind the light's plane.
                let lp = LightPoint {
                    x: 0.0,
                    y: 0.0,
                    z: f32::INFINITY,
                };
                return (lp, false);
            }
            let lp = LightPoint {
                x: (q.x / q.z) as f32,
                y: (q.y / q.z) as f32,
                z: (q.z / unit) as f32,
            };
            (lp, true)
        })
        .unzip();
    let (layers, triangles, occluder_grid) = match occluders {
        OccluderSource::Maps { grid: og, layers } => {
            if method.traces_triangles() {
                return Err(Error::invalid(
                    "method",
                    "traces triangles: pass the occluder mesh",
                ));
            }
            for (k, l) in layers.iter().enumerate() {
                let arg = format!("occluder layer {k}");
                if l.len() != og.len() {
                    return Err(Error::shape(
                        arg,
                        format!(
                            "has {} texels, expected {}x{}",
                            l.len(),
                            og.height,
                            og.width
                        ),
                    ));
                }
                check_depth(&arg, l)?;
            }
            let scaled: Vec<_> = layers.iter().map(|l| scaled_map(l, unit)).collect();
            (scaled, None, og)
        }
        OccluderSource::Mesh(mesh) => {
            if !method.traces_triangles() {
                return Err(Error::invalid(
                    "method",
                    "reads occluder maps: pass them, not the mesh",
                ));
            }
            mesh.validate("occluders")?;
            let mut ls = mesh.to_light_space(light);
            ls.iter_mut().for_each(|q| *q /= unit);
            check_lateral("occluders", &ls, unit)?;
            (vec![], Some(light_space_triangles(&ls, mesh.faces)), *grid)
        }
    };
    // The receiver map is not read when shading points.
    let inputs = ShadowInputs {
        grid: *grid,
        occluder_grid,
        light_size,
        receiver: &[],
        occluder_layers: layers.iter().map(|l| &l[..]).collect(),
        occluder_triangles: triangles.as_deref(),
    };
    Ok((shade_points(method, &inputs, &ls), inside))
}

/// World points of the receiver texels (texel centers at their receiver
/// depth) and their flat texel indices, in f64.
pub fn receiver_points(
    grid: &MapGrid,
    light: &RectLight,
    receiver: &[f32],
) -> (Vec<[f64; 3]>, Vec<u64>) {
    let w = grid.width;
    receiver
        .par_iter()
        .enumerate()
        .filter(|(_, z)| z.is_finite())
        .map(|(k, &z)| {
            let p = light.point_at(grid.x_of(k % w), grid.y_of(k / w), z as f64);
            (p.to_array(), k as u64)
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A texel-aligned plate at depth 2 over receivers at depth 4, times `s`.
    fn plate_maps(n: usize, s: f32) -> (Vec<f32>, Vec<f32>) {
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let front = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < 0.25 && y.abs() < 0.2 {
                    2.0 * s
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        (front, vec![4.0 * s; n * n])
    }

    #[test]
    fn depth_maps_at_any_power_of_two_scale_give_the_same_visibility() {
        // The kernels get depths in a unit near the receivers' (units.rs):
        // without it the SSM loses these shadows at 2^60 and 2^-70.
        let n = 24;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let ssm = Method::parse("ssm", None, None, None).unwrap();
        let bitmask = Method::parse("bitmask", Some(64), None, None).unwrap();
        for method in [ssm, bitmask] {
            let (f, r) = plate_maps(n, 1.0);
            let (base, _) = from_depth(&grid, &grid, [1.0, 0.6], &f, None, &r, method).unwrap();
            assert!(base.iter().any(|&v| v < 1e-6));
            for k in [-90, -70, 50, 60, 90] {
                let s = 2f32.powi(k);
                let (f, r) = plate_maps(n, s);
                let size = [s as f64, 0.6 * s as f64];
                let (v, _) = from_depth(&grid, &grid, size, &f, None, &r, method).unwrap();
                assert_eq!(v, base, "{method:?} at 2^{k}");
            }
        }
    }

    #[test]
    fn light_sizes_beyond_f32_relative_to_depth_are_refused() {
        let n = 8;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (f, r) = plate_maps(n, 1.0);
        let err = from_depth(
            &grid,
            &grid,
            [1e-35, 1.0],
            &f,
            None,
            &r,
            Method::parse("ssm", None, None, None).unwrap(),
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidArgument { ref arg, .. } if arg == "light_size"));
    }
}
