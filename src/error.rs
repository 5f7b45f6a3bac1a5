//! The one error type of the core. The Python bindings map it to exceptions in
//! one place (`python/errors.rs`); nothing else in the core knows about Python.

use thiserror::Error;

/// Every way a core call can refuse its input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// An argument has a wrong value (NaN, non-positive size, bad index...).
    /// `arg` names the argument as the user spelled it.
    #[error("{arg}: {msg}")]
    InvalidArgument { arg: String, msg: String },
    /// Arrays that must agree in shape do not.
    #[error("{arg}: {msg}")]
    ShapeMismatch { arg: String, msg: String },
    /// The request would allocate more than we are willing to before starting.
    #[error("{arg}: {msg}")]
    TooLarge { arg: String, msg: String },
    /// A call whose kernel counted more work than a call may do, stopped
    /// (`methods::bounded`); `arg` names the option whose size drove it.
    #[error("{arg}: {msg}")]
    TooCostly { arg: String, msg: String },
    /// `backend="gpu"` was asked for and no GPU adapter can be opened (none
    /// present, no driver, or switched off by SOFTSHADOW_GPU=off).
    #[error("no GPU available: {msg}")]
    GpuUnavailable { msg: String },
    /// The GPU device failed while running (out of memory, lost device).
    #[error("GPU failure: {msg}")]
    Gpu { msg: String },
    /// The call's `cancel::Token` was cancelled (Ctrl-C in Python) before
    /// it finished; nothing it computed is returned.
    #[error("interrupted")]
    Interrupted,
}

impl Error {
    pub fn invalid(arg: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::InvalidArgument {
            arg: arg.into(),
            msg: msg.into(),
        }
    }
    pub fn shape(arg: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::ShapeMismatch {
            arg: arg.into(),
            msg: msg.into(),
        }
    }
    pub fn gpu_unavailable(msg: impl Into<String>) -> Self {
        Error::GpuUnavailable { msg: msg.into() }
    }
    pub fn gpu(msg: impl Into<String>) -> Self {
        Error::Gpu { msg: msg.into() }
    }
    pub fn too_costly(arg: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::TooCostly {
            arg: arg.into(),
            msg: msg.into(),
        }
    }
    pub fn too_large(arg: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::TooLarge {
            arg: arg.into(),
            msg: msg.into(),
        }
    }
}

pub type Result<T> = std::result::Result<T, Error>;
