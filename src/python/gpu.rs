//! What the GPU adapter is. Without the `gpu` feature there is none, and
//! every GPU request raises GpuUnavailableError (the dispatch is the core's:
//! `crate::backend`).

use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    Err(crate::backend::not_built().into())
}
