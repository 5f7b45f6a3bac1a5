//! The error estimate as a Python class (`img.error_estimate`): frozen, its
//! numbers as the core measured them (`crate::error_estimate`).

use crate::error_estimate::ErrorEstimate;
use pyo3::prelude::*;

/// A result's error estimated from exact rays at a random subset of its
/// pixels: the mean |V - V_ref| over the pixels the exact rays find in
/// shadow, with a 95% confidence interval (docs/accuracy.md).
#[pyclass(frozen, module = "softshadow._core", name = "ErrorEstimate")]
#[derive(Clone)]
pub struct PyErrorEstimate(pub ErrorEstimate);

#[pymethods]
impl PyErrorEstimate {
    /// The estimated error over the shadowed pixels.
    #[getter]
    fn error(&self) -> f64 {
        self.0.error
    }
    /// The 95% confidence interval ``(low, high)``; ``(0.0, 1.0)`` when no
    /// traced pixel is in shadow.
    #[getter]
    fn interval(&self) -> (f64, f64) {
        (self.0.low, self.0.high)
    }
    /// Pixels traced with exact rays.
    #[getter]
    fn traced(&self) -> usize {
        self.0.traced
    }
    /// Of those, the pixels the exact rays found in shadow.
    #[getter]
    fn shadowed(&self) -> usize {
        self.0.shadowed
    }
    /// Light samples per traced pixel.
    #[getter]
    fn samples(&self) -> u32 {
        self.0.samples
    }
    /// Seconds the estimate took.
    #[getter]
    fn seconds(&self) -> f64 {
        self.0.seconds
    }
    fn __repr__(&self) -> String {
        let e = &self.0;
        format!(
            "ErrorEstimate(error={:.4}, interval=({:.4}, {:.4}), traced={}, shadowed={}, samples={}, seconds={:.3})",
            e.error, e.low, e.high, e.traced, e.shadowed, e.samples, e.seconds
        )
    }
}
