//! The one place where core errors become Python exceptions.

use crate::error::Error;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyErr;

pyo3::create_exception!(
    _core,
    GpuUnavailableError,
    PyRuntimeError,
    "backend=\"gpu\" was asked for and no GPU adapter can be opened (none present, no Vulkan driver, or SOFTSHADOW_GPU=off)."
);

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        match e {
            // All three are about an argument's value (or the size it asks for),
            // and the message starts with the argument's name.
            Error::InvalidArgument { .. }
            | Error::ShapeMismatch { .. }
            | Error::TooLarge { .. } => PyValueError::new_err(e.to_string()),
            Error::GpuUnavailable { .. } => GpuUnavailableError::new_err(e.to_string()),
            Error::Gpu { .. } => PyRuntimeError::new_err(e.to_string()),
        }
    }
}
