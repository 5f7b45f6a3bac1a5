//! softshadow: soft shadows cast by rectangular area lights.
//!
//! The core (everything but `python`) has no Python in it: the pyo3 bindings
//! are one thin layer behind the `python` feature.

// `!(x > 0.0)` is how the core says "not positive, or NaN": the negated
// comparison is the point, not an accident.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod depth_plane;
pub mod error;
pub mod extent;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod light;
pub mod memory;
pub mod mesh;
pub mod methods;
pub mod pipeline;
pub mod point_light;
pub mod raster;
pub mod units;

#[cfg(feature = "python")]
mod python;

pub use error::{Error, Result};
pub use light::{MapGrid, RectLight};
