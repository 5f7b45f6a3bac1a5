//! softshadow: soft shadows cast by rectangular area lights and the sun.
//!
//! The core (everything but `python`) has no Python in it: the pyo3 bindings
//! are one thin layer behind the `python` feature. A Rust user calls the
//! same dispatch the bindings do, picking the method with a typed config and
//! the backend with [`BackendChoice`]:
//!
//! ```
//! use softshadow::api::{shadow_map, MeshCall};
//! use softshadow::geom::mesh::MeshRef;
//! use softshadow::{BackendChoice, BitmaskConfig, Light, MethodConfig, AreaLight};
//!
//! // A unit plate at height 2 over a floor at 0, lit by a unit light 4 above:
//! // its umbra on the floor is one unit wide.
//! let quad = |y: f64, h: f64| [[-h, y, -h], [h, y, -h], [h, y, h], [-h, y, h]];
//! let faces = [[0u32, 1, 2], [0, 2, 3]];
//! let (plate, floor) = (quad(2.0, 0.5), quad(0.0, 4.0));
//! let light = AreaLight::rect([0.0, 4.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0])?;
//! let run = shadow_map(&MeshCall {
//!     occluders: MeshRef { vertices: &plate, faces: &faces },
//!     receivers: MeshRef { vertices: &floor, faces: &faces },
//!     light: &Light::Area(light),
//!     resolution: (64, 64),
//!     extent: None,
//!     method: MethodConfig::Bitmask(BitmaskConfig::new(Some(64), None, None, None, None)?),
//!     backend: BackendChoice::Cpu,
//!     threads: Some(1),
//!     estimate_error: None,
//! })?;
//! // The config that ran, every default filled in; visibility in [0, 1].
//! assert_eq!(run.method.passes(), 2);
//! let v = &run.output.visibility;
//! assert!(v.iter().all(|x| (0.0..=1.0).contains(x)) && v.iter().any(|&x| x < 0.01));
//! # Ok::<(), softshadow::Error>(())
//! ```

// `!(x > 0.0)` is how the core says "not positive, or NaN": the negated
// comparison is the point, not an accident.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// The stages, in the order the data flows: geometry in light space,
// rasterized light-view maps, the shadow methods that read them, and the
// pipelines that chain them; `gpu` mirrors raster and methods on the device.
pub mod api;
pub mod auto;
pub mod backend;
pub mod block_cache;
pub mod cancel;
pub mod error;
pub mod error_estimate;
pub mod eye;
pub mod frame;
pub mod geom;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod light_view;
pub mod memory;
pub mod methods;
pub mod pipeline;
pub mod raster;
pub mod threads;
pub mod timing;
pub mod trace;

#[cfg(test)]
mod layering;
#[cfg(feature = "python")]
mod python;

pub use backend::{Backend, BackendChoice};
pub use error::{Error, Result};
pub use geom::light::{AreaLight, MapGrid};
pub use geom::light_space::{Light, LightSpace};
pub use geom::sphere_light::SphereLight;
pub use geom::sun::DirectionalLight;
pub use methods::{BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};
