//! Framing of the user's depth maps: their checks, their depths and light
//! size in the kernels' depth unit (units.rs), and orthographic maps (a
//! sun's) as the kernels read them. Both backends start from these.

use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::geom::sun::{DirectionalLight, SunSpace};
use crate::geom::units::{farthest, scaled_map};
use crate::methods::{Input, Method};
use rayon::prelude::*;
use std::borrow::Cow;

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
/// method that reads maps, each map's size and depths. Returns the light's shape.
pub(crate) fn check_depth_inputs(
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_shape: LightShape,
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<LightShape> {
    let light_shape = light_shape.check("light_size")?;
    if !method.reads_input(Input::OccluderLayers) {
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
    Ok(light_shape)
}

/// The user's depth maps and light size in the kernels' depth unit (see
/// units.rs), shared by both backends; the maps are copied only when the unit
/// is not 1.
pub struct DepthInUnit<'a> {
    pub light_shape: LightShape,
    pub front: Cow<'a, [f32]>,
    pub back: Option<Cow<'a, [f32]>>,
    pub receiver: Cow<'a, [f32]>,
}

impl<'a> DepthInUnit<'a> {
    pub fn new(
        unit: f64,
        light_shape: LightShape,
        front: &'a [f32],
        back: Option<&'a [f32]>,
        receiver: &'a [f32],
    ) -> Result<DepthInUnit<'a>> {
        Ok(DepthInUnit {
            light_shape: light_shape.in_unit("light_size", unit)?,
            front: scaled_map(front, unit),
            back: back.map(|b| scaled_map(b, unit)),
            receiver: scaled_map(receiver, unit),
        })
    }
}

/// Orthographic depth maps as the kernels read them: the sun's space with
/// the depth origin at depth 0 and the maps' farthest depth as its range,
/// the maps in kernel depths, the grids in kernel tangents, the light's
/// kernel size. Depths must be finite and >= 0, or +inf where empty.
#[allow(clippy::type_complexity)]
pub fn orthographic_maps(
    grids: (&MapGrid, &MapGrid),
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    angular_size: [f64; 2],
) -> Result<(SunSpace, MapGrid, MapGrid, LightShape, Vec<Vec<f32>>)> {
    let sun = DirectionalLight::new([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], angular_size)?;
    let maps: Vec<(&str, &[f32])> = [("occluder_depth", front), ("receiver_depth", receiver)]
        .into_iter()
        .chain(back.map(|b| ("occluder_depth_back", b)))
        .collect();
    let mut range = 0f64;
    for (arg, m) in &maps {
        if let Some(k) = m.iter().position(|z| !(*z >= 0.0)) {
            return Err(Error::invalid(
                *arg,
                format!(
                    "orthographic depths must be >= 0 (from the depth origin) or +inf where \
                     empty; texel {k} holds {}",
                    m[k]
                ),
            ));
        }
        range = range.max(farthest(m));
    }
    let space = SunSpace::new(sun, glam::DVec3::ZERO, range);
    let kernel: Vec<Vec<f32>> = maps
        .iter()
        .map(|(_, m)| {
            m.iter()
                .map(|&z| space.kernel_depth(z as f64) as f32)
                .collect()
        })
        .collect();
    let s = LightSpace::Sun(space);
    let grid = |g: &MapGrid| MapGrid::new(g.width, g.height, s.kernel_extent([g.tx, g.ty]));
    Ok((
        space,
        grid(grids.0)?,
        grid(grids.1)?,
        sun.kernel_shape(),
        kernel,
    ))
}
