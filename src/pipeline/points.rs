//! Visibility at world points (`ShadowMap.sample`) from a shadow map's
//! occluders, and the world points of its receiver texels.

use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::geom::units::{check_lateral, check_unit, depth_unit, scaled_map};
use crate::methods::{Input, LightPoint, Method, ShadowInputs};
use glam::DVec3;
use rayon::prelude::*;

use crate::frame::{check_depth, light_space_triangles};
use crate::methods::{bounded, shade_points};

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
    light: &LightSpace,
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
    let light_shape = light.shape().in_unit("size", unit)?;
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
        OccluderSource::Maps { .. } if method.reads_input(Input::OccluderTriangles) => {
            return Err(Error::invalid(
                "method",
                format!(
                    "{:?} reads the occluder mesh and its maps; sampling a map at points \
                     supports the map methods (\"ssm\", \"bitmask\") and \"exact\" in this version",
                    method.name()
                ),
            ));
        }
        OccluderSource::Maps { grid: og, layers } => {
            if !method.reads_input(Input::OccluderLayers) {
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
            }
            // The user's depths (orthographic ones for the sun) -> the
            // kernels', which must be > 0 (or inf where empty).
            let kernel: Vec<Vec<f32>> = layers
                .iter()
                .map(|l| l.par_iter().map(|&z| light.kernel_depth(z)).collect())
                .collect();
            for (k, l) in kernel.iter().enumerate() {
                check_depth(&format!("occluder layer {k}"), l)?;
            }
            let scaled: Vec<Vec<f32>> = kernel
                .iter()
                .map(|l| scaled_map(l, unit).into_owned())
                .collect();
            (scaled, None, og)
        }
        OccluderSource::Mesh(mesh) => {
            if !method.traces() {
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
        light_shape,
        receiver: &[],
        occluder_layers: layers.iter().map(|l| &l[..]).collect(),
        occluder_triangles: triangles.as_deref(),
    };
    let v = bounded(method, &inputs, Some(&ls), "occluder_resolution", || {
        shade_points(method, &inputs, &ls)
    })?;
    Ok((v, inside))
}

/// World points of the receiver texels (texel centers at their receiver
/// depth) and their flat texel indices, in f64.
pub fn receiver_points(
    grid: &MapGrid,
    light: &LightSpace,
    receiver: &[f32],
) -> (Vec<[f64; 3]>, Vec<u64>) {
    let w = grid.width;
    receiver
        .par_iter()
        .enumerate()
        .filter(|(_, z)| z.is_finite())
        .map(|(k, &z)| {
            let z = light.kernel_depth(z) as f64;
            let p = light.point_at(grid.x_of(k % w), grid.y_of(k / w), z);
            (p.to_array(), k as u64)
        })
        .unzip()
}
