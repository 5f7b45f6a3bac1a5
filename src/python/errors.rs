//! The one place where core errors (and panics) become Python exceptions.

use crate::error::Error;
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    _core,
    GpuUnavailableError,
    PyRuntimeError,
    "backend=\"gpu\" was asked for and no GPU adapter can be opened (none present, no Vulkan driver, or SOFTSHADOW_GPU=off)."
);

/// `TooLargeError`: a request refused before allocating because it would
/// need too much memory; both a ValueError (a bad argument) and a
/// MemoryError. Two bases, which `create_exception!` cannot give, so the
/// class is made with `type()` when the module is first imported.
static TOO_LARGE: PyOnceLock<Py<PyType>> = PyOnceLock::new();

const TOO_LARGE_DOC: &str = "A request refused before allocating because it would need too much \
memory. Both a ValueError (a bad argument) and a MemoryError.";

/// The `TooLargeError` class, made once.
pub fn too_large_error(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    TOO_LARGE
        .get_or_try_init(py, || {
            let bases = PyTuple::new(
                py,
                [
                    py.get_type::<PyValueError>(),
                    py.get_type::<PyMemoryError>(),
                ],
            )?;
            let attrs = PyDict::new(py);
            attrs.set_item("__module__", "softshadow._core")?;
            attrs.set_item("__doc__", TOO_LARGE_DOC)?;
            let cls = py
                .get_type::<PyType>()
                .call1(("TooLargeError", bases, attrs))?;
            Ok::<_, PyErr>(cls.cast_into::<PyType>()?.unbind())
        })
        .map(|c| c.bind(py))
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let msg = e.to_string();
        match e {
            Error::GpuUnavailable { .. } => GpuUnavailableError::new_err(msg),
            Error::Gpu { .. } => PyRuntimeError::new_err(msg),
            // A cancelled token whose reason never reached Python (the
            // bindings raise the interpreter's own KeyboardInterrupt).
            Error::Interrupted => PyKeyboardInterrupt::new_err(msg),
            // About an argument's value; the message starts with its name.
            Error::InvalidArgument { .. }
            | Error::ShapeMismatch { .. }
            | Error::TooCostly { .. } => PyValueError::new_err(msg),
            // Refused before allocating: TooLargeError, both a ValueError
            // (a bad argument) and a MemoryError.
            Error::TooLarge { .. } => Python::attach(|py| match too_large_error(py) {
                Ok(cls) => PyErr::from_type(cls.clone(), msg),
                Err(_) => PyMemoryError::new_err(msg),
            }),
        }
    }
}

/// Runs `f`, turning a panic (a bug in the core: every refusal of input is an
/// `Error`) into a RuntimeError instead of pyo3's PanicException, which is a
/// BaseException that `except Exception` does not catch. Panics in rayon's
/// worker threads reach here too: rayon resumes them on the calling thread.
/// Nothing the core shares outlives a call, so the next call starts clean.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(PyRuntimeError::new_err(format!(
                "softshadow internal error (a bug; please report it with the input): {what}"
            )))
        }
    }
}
