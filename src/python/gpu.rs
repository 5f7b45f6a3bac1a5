//! The GPU side of the bindings: which backend runs the mesh pipeline, and
//! what the adapter is. Without the `gpu` feature every GPU request raises
//! GpuUnavailableError.

use crate::error::{Error, Result};
use crate::light::{MapGrid, RectLight};
use crate::mesh::MeshRef;
use crate::methods::Method;
use crate::pipeline::{self, MapSettings, ShadowResult, Timings};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Runs the mesh pipeline on `backend` ("cpu" or "gpu"; Python resolves "auto").
pub fn from_meshes(
    backend: &str,
    occ: MeshRef,
    rec: MeshRef,
    light: &RectLight,
    s: &MapSettings,
) -> Result<ShadowResult> {
    match backend {
        "cpu" => pipeline::from_meshes(occ, rec, light, s),
        #[cfg(feature = "gpu")]
        "gpu" => crate::gpu::from_meshes(occ, rec, light, s),
        #[cfg(not(feature = "gpu"))]
        "gpu" => Err(not_built()),
        other => Err(Error::invalid(
            "backend",
            format!("must be \"cpu\" or \"gpu\", got {other:?}"),
        )),
    }
}

/// Shades depth maps on `backend` ("cpu" or "gpu").
#[allow(clippy::too_many_arguments)]
pub fn from_depth(
    backend: &str,
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_size: [f64; 2],
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<(Vec<f32>, Timings)> {
    match backend {
        "cpu" => pipeline::from_depth(
            grid,
            occluder_grid,
            light_size,
            front,
            back,
            receiver,
            method,
        ),
        #[cfg(feature = "gpu")]
        "gpu" => crate::gpu::from_depth(
            grid,
            occluder_grid,
            light_size,
            front,
            back,
            receiver,
            method,
        ),
        #[cfg(not(feature = "gpu"))]
        "gpu" => Err(not_built()),
        other => Err(Error::invalid(
            "backend",
            format!("must be \"cpu\" or \"gpu\", got {other:?}"),
        )),
    }
}

#[cfg(not(feature = "gpu"))]
fn not_built() -> Error {
    Error::gpu_unavailable("this build of softshadow has no GPU backend (cargo feature `gpu`)")
}

/// Whether backend="gpu" can run: an adapter opens (software or not).
#[pyfunction]
pub fn gpu_available(py: Python<'_>) -> bool {
    #[cfg(feature = "gpu")]
    return py.detach(crate::gpu::available);
    #[cfg(not(feature = "gpu"))]
    {
        let _ = py;
        false
    }
}

/// The adapter backend="gpu" uses: name, backend, device_type, driver, software.
#[cfg(feature = "gpu")]
#[pyfunction]
pub fn gpu_info(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let info = py.detach(crate::gpu::info)?;
    let d = PyDict::new(py);
    d.set_item("name", info.name)?;
    d.set_item("backend", info.backend)?;
    d.set_item("device_type", info.device_type)?;
    d.set_item("driver", info.driver)?;
    d.set_item("software", info.software)?;
    Ok(d)
}

/// Without the `gpu` feature there is no adapter to describe.
#[cfg(not(feature = "gpu"))]
#[pyfunction]
pub fn gpu_info(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let _ = py;
    Err(not_built().into())
}
