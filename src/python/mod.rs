//! The pyo3 bindings: validate, borrow the arrays, release the GIL around the
//! work, return arrays without copies. Argument checks about Python types and
//! dtypes live in the Python package; value checks live in the core.

mod errors;
mod gpu;

use crate::light::{MapGrid, RectLight};
use crate::mesh::MeshRef;
use crate::methods::Method;
use crate::pipeline::{self, MapSettings, OccluderSource, Timings};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type Light = ([f64; 3], [f64; 3], [f64; 3], [f64; 2]);

fn light_of(l: Light) -> PyResult<RectLight> {
    Ok(RectLight::new(l.0, l.1, l.2, l.3)?)
}

/// Borrows a C-contiguous array as a slice, naming the argument if it is not.
fn slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    arg: &str,
    a: &'a numpy::PyReadonlyArray<'_, T, D>,
) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{arg}: must be a C-contiguous array")))
}

/// Reinterprets a (n, 3) array's buffer as n triples.
fn triples<'a, T: numpy::Element>(
    arg: &str,
    a: &'a PyReadonlyArray2<'_, T>,
) -> PyResult<&'a [[T; 3]]> {
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{arg}: must have shape (n, 3), got {:?}",
            a.shape()
        )));
    }
    let s = slice(arg, a)?;
    // SAFETY: [T; 3] has T's alignment and no padding; the buffer is
    // contiguous with a multiple of 3 elements, and it outlives the borrow.
    Ok(unsafe { std::slice::from_raw_parts(s.as_ptr() as *const [T; 3], s.len() / 3) })
}

/// A map dimension from a Python int: negative values are refused by name
/// (not as an OverflowError from the conversion); 0 is left to MapGrid.
fn count(arg: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v)
        .map_err(|_| PyValueError::new_err(format!("{arg}: must be at least 1, got {v}")))
}

/// Light samples per receiver from a Python int (range checked by Method::parse).
fn sample_count(v: Option<i64>) -> PyResult<Option<u32>> {
    v.map(|n| {
        u32::try_from(n)
            .map_err(|_| PyValueError::new_err(format!("samples: must be >= 1, got {n}")))
    })
    .transpose()
}

fn same_shape(arg: &str, got: &[usize], want: &[usize]) -> PyResult<()> {
    if got == want {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{arg}: shape {got:?} differs from {want:?}"
        )))
    }
}

fn timings_dict<'py>(py: Python<'py>, t: &Timings) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(*k, *v)?;
    }
    Ok(d)
}

fn map<'py>(py: Python<'py>, grid: &MapGrid, v: Vec<f32>) -> PyResult<Bound<'py, PyAny>> {
    let a = Array2::from_shape_vec((grid.height, grid.width), v)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// Validates a light and returns its frame (u, v, n).
#[pyfunction]
fn light_frame(light: Light) -> PyResult<([f64; 3], [f64; 3], [f64; 3])> {
    errors::guard(|| {
        let l = light_of(light)?;
        Ok((l.u.to_array(), l.v.to_array(), l.n.to_array()))
    })
}

/// Meshes -> light-view maps -> visibility.
#[pyfunction]
#[pyo3(signature = (occ_vertices, occ_faces, rec_vertices, rec_faces, light, width, height, extent, passes, method, samples=None, hierarchy=None, precision=None, occluder_resolution=None, backend="cpu"))]
#[allow(clippy::too_many_arguments)]
fn shadow_map_from_meshes<'py>(
    py: Python<'py>,
    occ_vertices: PyReadonlyArray2<'py, f64>,
    occ_faces: PyReadonlyArray2<'py, u32>,
    rec_vertices: PyReadonlyArray2<'py, f64>,
    rec_faces: PyReadonlyArray2<'py, u32>,
    light: Light,
    width: i64,
    height: i64,
    extent: Option<(f64, f64)>,
    passes: i64,
    method: &str,
    samples: Option<i64>,
    hierarchy: Option<bool>,
    precision: Option<&str>,
    occluder_resolution: Option<(i64, i64)>,
    backend: &str,
) -> PyResult<Bound<'py, PyDict>> {
    errors::guard(|| {
        let light = light_of(light)?;
        let method = Method::parse(method, sample_count(samples)?, hierarchy, precision)?;
        let (width, height) = (count("resolution", width)?, count("resolution", height)?);
        let occluder_resolution = match occluder_resolution {
            Some((w, h)) => Some((
                count("occluder_resolution", w)?,
                count("occluder_resolution", h)?,
            )),
            None => None,
        };
        let passes = u32::try_from(passes).map_err(|_| {
            PyValueError::new_err(format!("passes: must be in [1, 8], got {passes}"))
        })?;
        let occ = MeshRef {
            vertices: triples("occluders", &occ_vertices)?,
            faces: triples("occluders", &occ_faces)?,
        };
        let rec = MeshRef {
            vertices: triples("receivers", &rec_vertices)?,
            faces: triples("receivers", &rec_faces)?,
        };
        let settings = MapSettings {
            width,
            height,
            extent: extent.map(|e| [e.0, e.1]),
            occluder_resolution,
            passes,
            method,
        };
        let r = py.detach(|| gpu::from_meshes(backend, occ, rec, &light, &settings))?;
        let d = PyDict::new(py);
        d.set_item("extent", (r.grid.tx, r.grid.ty))?;
        d.set_item("timings", timings_dict(py, &r.timings)?)?;
        d.set_item("visibility", map(py, &r.grid, r.visibility)?)?;
        d.set_item("receiver_depth", map(py, &r.grid, r.receiver)?)?;
        for (key, m) in [
            ("occluder_depth", r.occluder_front),
            ("occluder_depth_back", r.occluder_back),
        ] {
            match m {
                Some(m) => d.set_item(key, map(py, &r.occluder_grid, m)?)?,
                None => d.set_item(key, py.None())?,
            }
        }
        let middle = r
            .occluder_middle
            .into_iter()
            .map(|m| map(py, &r.occluder_grid, m))
            .collect::<PyResult<Vec<_>>>()?;
        d.set_item("occluder_depth_middle", middle)?;
        Ok(d)
    })
}

/// Depth maps -> visibility.
#[pyfunction]
#[pyo3(signature = (occluder_depth, occluder_depth_back, receiver_depth, light_size, extent, method, samples=None, hierarchy=None, precision=None, backend="cpu"))]
#[allow(clippy::too_many_arguments)]
fn shadow_map_from_depth<'py>(
    py: Python<'py>,
    occluder_depth: PyReadonlyArray2<'py, f32>,
    occluder_depth_back: Option<PyReadonlyArray2<'py, f32>>,
    receiver_depth: PyReadonlyArray2<'py, f32>,
    light_size: [f64; 2],
    extent: (f64, f64),
    method: &str,
    samples: Option<i64>,
    hierarchy: Option<bool>,
    precision: Option<&str>,
    backend: &str,
) -> PyResult<Bound<'py, PyDict>> {
    errors::guard(|| {
        let method = Method::parse(method, sample_count(samples)?, hierarchy, precision)?;
        let shape = receiver_depth.shape();
        // The occluder maps may be coarser or finer than the receiver map (same extent).
        let oshape = occluder_depth.shape();
        if let Some(b) = &occluder_depth_back {
            same_shape("occluder_depth_back", b.shape(), oshape)?;
        }
        let grid = MapGrid::new(shape[1], shape[0], [extent.0, extent.1])?;
        let occluder_grid = MapGrid::new(oshape[1], oshape[0], [extent.0, extent.1])?;
        let front = slice("occluder_depth", &occluder_depth)?;
        let back = match &occluder_depth_back {
            Some(b) => Some(slice("occluder_depth_back", b)?),
            None => None,
        };
        let receiver = slice("receiver_depth", &receiver_depth)?;
        let (v, t) = py.detach(|| {
            gpu::from_depth(
                backend,
                &grid,
                &occluder_grid,
                light_size,
                front,
                back,
                receiver,
                method,
            )
        })?;
        let d = PyDict::new(py);
        d.set_item("timings", timings_dict(py, &t)?)?;
        d.set_item("visibility", map(py, &grid, v)?)?;
        Ok(d)
    })
}

/// Visibility at world points from a shadow map's occluders: its occluder maps
/// (map methods) or the occluder mesh (ray-traced methods).
#[pyfunction]
#[pyo3(signature = (light, extent, width, height, points, method, samples=None, hierarchy=None, precision=None, occluder_depth=None, occluder_depth_back=None, occ_vertices=None, occ_faces=None, occluder_depth_middle=None))]
#[allow(clippy::too_many_arguments)]
fn sample_points<'py>(
    py: Python<'py>,
    light: Light,
    extent: (f64, f64),
    width: i64,
    height: i64,
    points: PyReadonlyArray2<'py, f64>,
    method: &str,
    samples: Option<i64>,
    hierarchy: Option<bool>,
    precision: Option<&str>,
    occluder_depth: Option<PyReadonlyArray2<'py, f32>>,
    occluder_depth_back: Option<PyReadonlyArray2<'py, f32>>,
    occ_vertices: Option<PyReadonlyArray2<'py, f64>>,
    occ_faces: Option<PyReadonlyArray2<'py, u32>>,
    occluder_depth_middle: Option<Vec<PyReadonlyArray2<'py, f32>>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    errors::guard(|| {
        let light = light_of(light)?;
        let method = Method::parse(method, sample_count(samples)?, hierarchy, precision)?;
        let (width, height) = (count("resolution", width)?, count("resolution", height)?);
        let grid = MapGrid::new(width, height, [extent.0, extent.1])?;
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
                    grid: MapGrid::new(oshape[1], oshape[0], [extent.0, extent.1])?,
                    layers,
                }
            }
            (None, Some(v), Some(f)) => OccluderSource::Mesh(MeshRef {
                vertices: triples("occluders", v)?,
                faces: triples("occluders", f)?,
            }),
            _ => {
                return Err(PyValueError::new_err(
                    "occluders: pass either occluder_depth (and occluder_depth_back) or occ_vertices and occ_faces",
                ))
            }
        };
        let pts = triples("points", &points)?;
        let (v, inside) =
            py.detach(|| pipeline::sample_points(&grid, &light, source, pts, method))?;
        Ok((
            v.into_pyarray(py).into_any(),
            inside.into_pyarray(py).into_any(),
        ))
    })
}

/// World points of the receiver texels and their flat indices.
#[pyfunction]
fn receiver_points<'py>(
    py: Python<'py>,
    receiver_depth: PyReadonlyArray2<'py, f32>,
    light: Light,
    extent: (f64, f64),
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    errors::guard(|| {
        let light = light_of(light)?;
        let shape = receiver_depth.shape();
        let grid = MapGrid::new(shape[1], shape[0], [extent.0, extent.1])?;
        let rec = slice("receiver_depth", &receiver_depth)?;
        pipeline::check_depth("receiver_depth", rec)?;
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
fn _panic_for_tests(py: Python<'_>, in_worker: bool) -> PyResult<()> {
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

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(light_frame, m)?)?;
    m.add_function(wrap_pyfunction!(shadow_map_from_meshes, m)?)?;
    m.add_function(wrap_pyfunction!(shadow_map_from_depth, m)?)?;
    m.add_function(wrap_pyfunction!(sample_points, m)?)?;
    m.add_function(wrap_pyfunction!(receiver_points, m)?)?;
    m.add_function(wrap_pyfunction!(gpu::gpu_available, m)?)?;
    m.add_function(wrap_pyfunction!(gpu::gpu_info, m)?)?;
    m.add(
        "GpuUnavailableError",
        m.py().get_type::<errors::GpuUnavailableError>(),
    )?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
