//! What the entry points return: typed results holding numpy arrays made
//! from the core's vectors without a copy.

use super::configs;
use crate::api::{DepthOutput, Run};
use crate::frame::ShadowResult;
use crate::geom::light::MapGrid;
use crate::geom::light_space::LightSpace;
use crate::timing::Timings;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A (H, W) numpy array owning `v` (moved, not copied).
pub fn map(py: Python<'_>, grid: &MapGrid, v: Vec<f32>) -> PyResult<Py<PyAny>> {
    let a = Array2::from_shape_vec((grid.height, grid.width), v)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any().unbind())
}

/// A sun's orthographic maps' depth origin and range (None for a rectangle).
pub fn sun_depth(space: Option<&LightSpace>) -> (Option<(f64, f64, f64)>, Option<f64>) {
    match space {
        Some(LightSpace::Sun(s)) => (Some(s.origin.into()), Some(s.depth_range)),
        _ => (None, None),
    }
}

fn timings_dict<'py>(py: Python<'py>, t: &Timings) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(*k, *v)?;
    }
    Ok(d)
}

/// A shadow map of meshes: the visibility and the light-view maps it came
/// from, with the config, backend and threads that ran it.
#[pyclass(frozen, module = "softshadow._core", name = "MeshShadowResult")]
pub struct MeshShadowResult {
    /// (H, W) float32 visibility.
    #[pyo3(get)]
    visibility: Py<PyAny>,
    /// (H, W) float32 receiver depth, inf where none.
    #[pyo3(get)]
    receiver_depth: Py<PyAny>,
    /// Front occluder layer; None for methods that read no layers.
    #[pyo3(get)]
    occluder_depth: Option<Py<PyAny>>,
    /// Back occluder layer; None with one pass or no layers.
    #[pyo3(get)]
    occluder_depth_back: Option<Py<PyAny>>,
    /// Peeled layers between front and back, nearest first.
    #[pyo3(get)]
    occluder_depth_middle: Vec<Py<PyAny>>,
    /// Tangent half-extents (tx, ty); world half-extents for the sun.
    #[pyo3(get)]
    extent: (f64, f64),
    /// For the sun: the orthographic maps' depth origin and depth range.
    #[pyo3(get)]
    depth_origin: Option<(f64, f64, f64)>,
    #[pyo3(get)]
    depth_range: Option<f64>,
    timings: Timings,
    /// The config that ran.
    #[pyo3(get)]
    method: Py<PyAny>,
    /// "cpu" or "gpu".
    #[pyo3(get)]
    backend: &'static str,
    /// Worker threads the CPU stages could use.
    #[pyo3(get)]
    threads: usize,
    /// What `Auto` with a target decided: (name, taken, why) per decision.
    #[pyo3(get)]
    plan: Option<Vec<(&'static str, bool, String)>>,
    /// The setting the plan chose, before runs checked against its
    /// estimate replaced it (None without a plan).
    #[pyo3(get)]
    planned_method: Option<Py<PyAny>>,
    /// The error estimate (`estimate_error=True`, or `Auto` with a target),
    /// else None.
    #[pyo3(get)]
    error_estimate: Option<Py<super::estimate::PyErrorEstimate>>,
}

#[pymethods]
impl MeshShadowResult {
    /// Seconds per stage, in the order they ran.
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        timings_dict(py, &self.timings)
    }
}

/// A plan as Python reads it: (name, taken, why) per decision.
pub(crate) fn plan_tuples(
    plan: Option<crate::auto::Plan>,
) -> Option<Vec<(&'static str, bool, String)>> {
    plan.map(|p| {
        p.decisions
            .into_iter()
            .map(|d| (d.name, d.taken, d.why))
            .collect()
    })
}

impl MeshShadowResult {
    pub fn new(py: Python<'_>, run: Run<ShadowResult>) -> PyResult<Self> {
        let r = run.output;
        let og = r.occluder_grid;
        let [ex, ey] = r.user_extent();
        let layer = |m: Option<Vec<f32>>| m.map(|m| map(py, &og, m)).transpose();
        let error_estimate = r
            .estimate
            .map(|e| Py::new(py, super::estimate::PyErrorEstimate(e)))
            .transpose()?;
        let planned_method = (run.plan.as_ref())
            .and_then(|p| p.planned)
            .map(|m| configs::to_py(py, &m))
            .transpose()?;
        Ok(MeshShadowResult {
            visibility: map(py, &r.grid, r.visibility)?,
            receiver_depth: map(py, &r.grid, r.receiver)?,
            occluder_depth: layer(r.occluder_front)?,
            occluder_depth_back: layer(r.occluder_back)?,
            occluder_depth_middle: r
                .occluder_middle
                .into_iter()
                .map(|m| map(py, &og, m))
                .collect::<PyResult<_>>()?,
            extent: (ex, ey),
            depth_origin: sun_depth(Some(&r.light_space)).0,
            depth_range: sun_depth(Some(&r.light_space)).1,
            timings: r.timings,
            method: configs::to_py(py, &run.method)?,
            backend: run.backend.name(),
            threads: run.threads,
            plan: plan_tuples(run.plan),
            planned_method,
            error_estimate,
        })
    }
}

/// Depth maps shaded: the visibility, with the config, backend and threads
/// that ran it.
#[pyclass(frozen, module = "softshadow._core", name = "DepthShadowResult")]
pub struct DepthShadowResult {
    /// (H, W) float32 visibility, on the receiver map's grid.
    #[pyo3(get)]
    visibility: Py<PyAny>,
    /// For orthographic maps: the depth range of their kernel space.
    #[pyo3(get)]
    depth_range: Option<f64>,
    timings: Timings,
    #[pyo3(get)]
    method: Py<PyAny>,
    #[pyo3(get)]
    backend: &'static str,
    #[pyo3(get)]
    threads: usize,
}

#[pymethods]
impl DepthShadowResult {
    /// Seconds per stage, in the order they ran.
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        timings_dict(py, &self.timings)
    }
}

impl DepthShadowResult {
    pub fn new(py: Python<'_>, grid: &MapGrid, run: Run<DepthOutput>) -> PyResult<Self> {
        let out = run.output;
        Ok(DepthShadowResult {
            visibility: map(py, grid, out.visibility)?,
            depth_range: out.depth_range,
            timings: out.timings,
            method: configs::to_py(py, &run.method)?,
            backend: run.backend.name(),
            threads: run.threads,
        })
    }
}
