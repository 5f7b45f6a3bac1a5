//! A scene's preparation as a Python object (`softshadow.Scene` holds one
//! and passes it to every `render`): the core's `eye::prepared::Prepared`,
//! shared between threads; the bindings only hand it over.

use crate::eye::prepared::Prepared;
use pyo3::prelude::*;

/// What renders of a scene built and kept for the next ones (the checked
/// triangles, the shadow rays' BVH per light orientation).
#[pyclass(frozen, module = "softshadow._core", name = "Prepared")]
#[derive(Default)]
pub struct PyPrepared(pub Prepared);

#[pymethods]
impl PyPrepared {
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Forgets what was kept.
    fn clear(&self) {
        self.0.clear();
    }

    /// Whether the triangles are kept, and how many trees.
    #[getter]
    fn held(&self) -> (bool, usize) {
        self.0.held()
    }

    fn __repr__(&self) -> String {
        format!("{:?}", self.0)
    }
}
