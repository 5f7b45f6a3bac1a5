//! The one place where core errors become Python exceptions.

use crate::error::Error;
use pyo3::exceptions::PyValueError;
use pyo3::PyErr;

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        match e {
            // All three are about an argument's value (or the size it asks for),
            // and the message starts with the argument's name.
            Error::InvalidArgument { .. }
            | Error::ShapeMismatch { .. }
            | Error::TooLarge { .. } => PyValueError::new_err(e.to_string()),
        }
    }
}
