//! The entry points: convert, release the GIL, call the core's dispatch
//! (`crate::backend`), wrap the result.

use super::configs::{method_arg, Loose};
use super::convert::{
    light_of, mesh, opt_float, opt_int, opt_string, same_shape, slice, space_of, triples, Backend,
    Light,
};
use super::errors;
use super::results::{DepthShadowResult, MeshShadowResult};
use crate::api::{self, DepthCall, MeshCall, SceneCall};
use crate::error_estimate::Draw;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::{sphere_has_no_space, Light as CoreLight};
use crate::methods::MethodConfig;
use crate::pipeline::{self, OccluderSource};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Validates a light and returns its frame (u, v, n).
#[pyfunction]
pub fn light_frame(light: Light) -> PyResult<([f64; 3], [f64; 3], [f64; 3])> {
    errors::guard(|| {
        Ok(match light_of(light)? {
            CoreLight::Area(l) => (l.u.to_array(), l.v.to_array(), l.n.to_array()),
            CoreLight::Sun(l) => (l.u.to_array(), l.v.to_array(), l.n.to_array()),
            CoreLight::Sphere(_) => return Err(sphere_has_no_space().into()),
        })
    })
}

/// Checks a mesh's values (finite vertices, face indices in range); `arg`
/// names it in the error.
#[pyfunction]
pub fn check_mesh<'py>(
    arg: &str,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
) -> PyResult<()> {
    errors::guard(|| Ok(mesh(arg, &vertices, &faces)?.validate(arg)?))
}

/// Meshes -> light-view maps -> visibility.
#[pyfunction]
#[pyo3(signature = (occ_vertices, occ_faces, rec_vertices, rec_faces, light, resolution, extent, method, *, passes=None, samples=None, occluder_resolution=None, hierarchy=None, precision=None, backend=Backend::CPU, threads=None, estimate_error=None))]
#[allow(clippy::too_many_arguments)]
pub fn shadow_map_from_meshes<'py>(
    py: Python<'py>,
    occ_vertices: PyReadonlyArray2<'py, f64>,
    occ_faces: PyReadonlyArray2<'py, u32>,
    rec_vertices: PyReadonlyArray2<'py, f64>,
    rec_faces: PyReadonlyArray2<'py, u32>,
    light: Light,
    resolution: &Bound<'py, PyAny>,
    extent: Option<(f64, f64)>,
    method: &Bound<'py, PyAny>,
    passes: Option<Bound<'py, PyAny>>,
    samples: Option<Bound<'py, PyAny>>,
    occluder_resolution: Option<Bound<'py, PyAny>>,
    hierarchy: Option<Bound<'py, PyAny>>,
    precision: Option<Bound<'py, PyAny>>,
    backend: Backend,
    threads: Option<Bound<'py, PyAny>>,
    estimate_error: Option<Bound<'py, PyAny>>,
) -> PyResult<MeshShadowResult> {
    errors::guard(|| {
        let light = light_of(light)?;
        let loose = Loose {
            passes,
            samples,
            occluder_resolution,
            hierarchy,
            precision,
        };
        let call = MeshCall {
            occluders: mesh("occluders", &occ_vertices, &occ_faces)?,
            receivers: mesh("receivers", &rec_vertices, &rec_faces)?,
            light: &light,
            resolution: super::convert::resolution("resolution", resolution)?,
            extent: extent.map(|e| [e.0, e.1]),
            method: method_arg(method, &loose)?,
            backend: backend.0,
            threads: opt_int("threads", threads.as_ref())?,
            estimate_error: opt_string("estimate_error", estimate_error.as_ref())?
                .as_deref()
                .map(Draw::parse)
                .transpose()?,
        };
        let run = super::interrupt::run(py, || api::shadow_map(&call))?;
        MeshShadowResult::new(py, run)
    })
}

/// A scene shadowing itself (one mesh of every mesh) -> light-view maps ->
/// visibility.
#[pyfunction]
#[pyo3(signature = (vertices, faces, light, resolution, extent, method, *, normal_offset=None, depth_bias=None, passes=None, samples=None, occluder_resolution=None, hierarchy=None, precision=None, backend=Backend::CPU, threads=None, estimate_error=None))]
#[allow(clippy::too_many_arguments)]
pub fn shadow_map_from_scene<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, u32>,
    light: Light,
    resolution: &Bound<'py, PyAny>,
    extent: Option<(f64, f64)>,
    method: &Bound<'py, PyAny>,
    normal_offset: Option<Bound<'py, PyAny>>,
    depth_bias: Option<Bound<'py, PyAny>>,
    passes: Option<Bound<'py, PyAny>>,
    samples: Option<Bound<'py, PyAny>>,
    occluder_resolution: Option<Bound<'py, PyAny>>,
    hierarchy: Option<Bound<'py, PyAny>>,
    precision: Option<Bound<'py, PyAny>>,
    backend: Backend,
    threads: Option<Bound<'py, PyAny>>,
    estimate_error: Option<Bound<'py, PyAny>>,
) -> PyResult<MeshShadowResult> {
    errors::guard(|| {
        let light = light_of(light)?;
        let loose = Loose {
            passes,
            samples,
            occluder_resolution,
            hierarchy,
            precision,
        };
        let call = SceneCall {
            scene: mesh("meshes", &vertices, &faces)?,
            light: &light,
            resolution: super::convert::resolution("resolution", resolution)?,
            extent: extent.map(|e| [e.0, e.1]),
            method: method_arg(method, &loose)?,
            bias: crate::eye::Bias::new(
                opt_float("normal_offset", normal_offset.as_ref())?,
                opt_float("depth_bias", depth_bias.as_ref())?,
            )?,
            backend: backend.0,
            threads: opt_int("threads", threads.as_ref())?,
            estimate_error: opt_string("estimate_error", estimate_error.as_ref())?
                .as_deref()
                .map(Draw::parse)
                .transpose()?,
        };
        let run = super::interrupt::run(py, || api::scene_shadow_map(&call))?;
        MeshShadowResult::new(py, run)
    })
}

/// Depth maps -> visibility.
#[pyfunction]
#[pyo3(signature = (occluder_depth, occluder_depth_back, receiver_depth, light_size, extent, method, *, angular_size=None, passes=None, samples=None, occluder_resolution=None, hierarchy=None, precision=None, backend=Backend::CPU, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn shadow_map_from_depth<'py>(
    py: Python<'py>,
    occluder_depth: PyReadonlyArray2<'py, f32>,
    occluder_depth_back: Option<PyReadonlyArray2<'py, f32>>,
    receiver_depth: PyReadonlyArray2<'py, f32>,
    light_size: Option<[f64; 2]>,
    extent: (f64, f64),
    method: &Bound<'py, PyAny>,
    angular_size: Option<[f64; 2]>,
    passes: Option<Bound<'py, PyAny>>,
    samples: Option<Bound<'py, PyAny>>,
    occluder_resolution: Option<Bound<'py, PyAny>>,
    hierarchy: Option<Bound<'py, PyAny>>,
    precision: Option<Bound<'py, PyAny>>,
    backend: Backend,
    threads: Option<Bound<'py, PyAny>>,
) -> PyResult<DepthShadowResult> {
    errors::guard(|| {
        let loose = Loose {
            passes,
            samples,
            occluder_resolution,
            hierarchy,
            precision,
        };
        let method = method_arg(method, &loose)?;
        let shape = receiver_depth.shape();
        // The occluder maps may be coarser or finer than the receiver map (same extent).
        let oshape = occluder_depth.shape();
        if let Some(b) = &occluder_depth_back {
            same_shape("occluder_depth_back", b.shape(), oshape)?;
        }
        let grid = MapGrid::new(shape[1], shape[0], [extent.0, extent.1])?;
        let occluder_grid = MapGrid::new(oshape[1], oshape[0], [extent.0, extent.1])?;
        let light_size = match (light_size, angular_size) {
            (Some(s), None) => s,
            (None, Some(_)) => [0.0, 0.0],
            _ => {
                return Err(PyValueError::new_err(
                    "light_size: pass either light_size (a rectangle's) or angular_size \
                     (a directional light's orthographic maps)",
                ))
            }
        };
        let call = DepthCall {
            grid,
            occluder_grid,
            light_shape: LightShape::rect(light_size),
            sun: angular_size,
            front: slice("occluder_depth", &occluder_depth)?,
            back: match &occluder_depth_back {
                Some(b) => Some(slice("occluder_depth_back", b)?),
                None => None,
            },
            receiver: slice("receiver_depth", &receiver_depth)?,
            method,
            backend: backend.0,
            threads: opt_int("threads", threads.as_ref())?,
        };
        let run = super::interrupt::run(py, || api::shadow_map_from_depth(&call))?;
        DepthShadowResult::new(py, &grid, run)
    })
}

/// Visibility at world points from a shadow map's occluders: its occluder
/// maps (map methods) or the occluder mesh (ray-traced methods). `method` is
/// the config the map ran with.
#[pyfunction]
#[pyo3(signature = (light, extent, resolution, points, method, *, occluder_depth=None, occluder_depth_back=None, occ_vertices=None, occ_faces=None, occluder_depth_middle=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn sample_points<'py>(
    py: Python<'py>,
    light: Light,
    extent: (f64, f64),
    resolution: (i64, i64),
    points: PyReadonlyArray2<'py, f64>,
    method: &Bound<'py, PyAny>,
    occluder_depth: Option<PyReadonlyArray2<'py, f32>>,
    occluder_depth_back: Option<PyReadonlyArray2<'py, f32>>,
    occ_vertices: Option<PyReadonlyArray2<'py, f64>>,
    occ_faces: Option<PyReadonlyArray2<'py, u32>>,
    occluder_depth_middle: Option<Vec<PyReadonlyArray2<'py, f32>>>,
    threads: Option<Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    errors::guard(|| {
        let light = space_of(light)?;
        let method: MethodConfig = method_arg(method, &Loose::none())?;
        let (w, h) = crate::methods::config::check_resolution("resolution", resolution)?;
        let grid = MapGrid::new(w, h, light.kernel_extent([extent.0, extent.1]))?;
        let middle = occluder_depth_middle.unwrap_or_default();
        let source = match (&occluder_depth, &occ_vertices, &occ_faces) {
            (Some(front), None, None) => {
                let oshape = front.shape();
                // Front first, the peeled layers, back last (the order of the map
                // pipeline's layers).
                let mut layers = vec![slice("occluder_depth", front)?];
                for m in &middle {
                    same_shape("occluder_depth_middle", m.shape(), oshape)?;
                    layers.push(slice("occluder_depth_middle", m)?);
                }
                if let Some(b) = &occluder_depth_back {
                    same_shape("occluder_depth_back", b.shape(), oshape)?;
                    layers.push(slice("occluder_depth_back", b)?);
                }
                OccluderSource::Maps {
                    grid: MapGrid::new(oshape[1], oshape[0], light.kernel_extent([extent.0, extent.1]))?,
                    layers,
                }
            }
            (None, Some(v), Some(f)) => OccluderSource::Mesh(mesh("occluders", v, f)?),
            _ => {
                return Err(PyValueError::new_err(
                    "occluders: pass either occluder_depth (and occluder_depth_back) or occ_vertices and occ_faces",
                ))
            }
        };
        let pts = triples("points", &points)?;
        let threads = opt_int("threads", threads.as_ref())?;
        let (v, inside) =
            py.detach(|| api::sample_points(&grid, &light, source, pts, &method, threads))?;
        Ok((
            v.into_pyarray(py).into_any(),
            inside.into_pyarray(py).into_any(),
        ))
    })
}

/// World points of the receiver texels and their flat indices.
#[pyfunction]
pub fn receiver_points<'py>(
    py: Python<'py>,
    receiver_depth: PyReadonlyArray2<'py, f32>,
    light: Light,
    extent: (f64, f64),
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    errors::guard(|| {
        let light = space_of(light)?;
        let shape = receiver_depth.shape();
        let grid = MapGrid::new(
            shape[1],
            shape[0],
            light.kernel_extent([extent.0, extent.1]),
        )?;
        let rec = slice("receiver_depth", &receiver_depth)?;
        // The kernels' depths must be > 0 (or inf): a sun's orthographic
        // depths start at 0 and are checked once converted.
        let kernel: Vec<f32> = rec.iter().map(|&z| light.kernel_depth(z)).collect();
        crate::frame::check_depth("receiver_depth", &kernel)?;
        let (pts, idx) = py.detach(|| pipeline::receiver_points(&grid, &light, rec));
        let n = pts.len();
        let flat: Vec<f64> = pts.into_iter().flatten().collect();
        let pts = Array2::from_shape_vec((n, 3), flat)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok((
            pts.into_pyarray(py).into_any(),
            idx.into_pyarray(py).into_any(),
        ))
    })
}

/// Panics on purpose, in a rayon worker thread when `in_worker`: lets the
/// tests check that a panic in the core becomes a RuntimeError and leaves the
/// module usable. Not part of the API.
#[pyfunction]
pub fn _panic_for_tests(py: Python<'_>, in_worker: bool) -> PyResult<()> {
    errors::guard(|| {
        py.detach(|| {
            if in_worker {
                rayon::join(|| (), || panic!("deliberate panic in a worker thread"));
            } else {
                panic!("deliberate panic");
            }
        });
        Ok(())
    })
}
