//! softshadow: soft shadows cast by rectangular area lights.
//!
//! The core (everything but `python`) has no Python in it: the pyo3 bindings
//! are one thin layer behind the `python` feature.

// `!(x > 0.0)` is how the core says "not positive, or NaN": the negated
// comparison is the point, not an accident.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// The stages, in the order the data flows: geometry in light space,
// rasterized light-view maps, the shadow methods that read them, and the
// pipelines that chain them; `gpu` mirrors raster and methods on the device.
pub mod backend;
pub mod error;
pub mod geom;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod memory;
pub mod methods;
pub mod pipeline;
pub mod raster;
pub mod threads;

#[cfg(feature = "python")]
mod python;

pub use backend::{Backend, BackendChoice};
pub use error::{Error, Result};
pub use geom::light::{MapGrid, RectLight};
pub use methods::{BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};
