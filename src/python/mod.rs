//! The pyo3 bindings (`softshadow._core`). They only convert: check Python
//! types, borrow arrays, release the GIL around the work, return arrays
//! without copies. Value checks, the method table, defaults and limits, and
//! the backend dispatch live in the core; Python reads them from here.
//!
//! * `convert.rs`: Python values to core values (TypeError naming the argument).
//! * `keyword_class.rs`: the class of every config with a keyword form
//!   (`Ssm`, `Bitmask`, `Exact`, `PCSS`, `Smoothies`, and a new method's),
//!   made at import from the core's table; nothing here names them.
//! * `config_class.rs`: the macro that makes a class from one description
//!   of its options, for the configs written by hand: `configs.rs` (`Auto`,
//!   the conversions of every config, the string form) and
//!   `shadow_configs.rs` (ShadowMapping and its parts).
//! * `camera.rs`: the eye view's `Camera`; `lights.rs`: `RectLight`,
//!   `DirectionalLight`.
//! * `entry.rs`: the entry points.
//! * `eye.rs`: the eye view's `render` and its result.
//! * `results.rs`: the typed results.
//! * `capabilities.rs`: the method table and limits.
//! * `errors.rs`: core errors and panics to Python exceptions.
//! * `gpu.rs`: what the GPU adapter is.

mod camera;
mod capabilities;
mod config_class;
mod configs;
mod convert;
mod entry;
mod errors;
mod estimate;
mod eye;
mod gpu;
mod interrupt;
mod keyword_class;
mod lights;
mod prepared;
mod results;
mod shadow_configs;

use pyo3::prelude::*;

/// The extension's allocations keep their large blocks between calls
/// (crate::block_cache: page faults were half an eye-view render's time).
#[global_allocator]
static ALLOCATOR: crate::block_cache::BlockCache = crate::block_cache::BlockCache::new();

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    ALLOCATOR.configure_from_env();
    let mut configs = configs::register(m)?;
    configs.extend(shadow_configs::register(m)?);
    m.add_class::<camera::PyCamera>()?;
    m.add_class::<lights::PyRectLight>()?;
    m.add_class::<lights::PyDiskLight>()?;
    m.add_class::<lights::PySphereLight>()?;
    m.add_class::<lights::PyDirectionalLight>()?;
    m.add_class::<results::MeshShadowResult>()?;
    m.add_class::<results::DepthShadowResult>()?;
    m.add_class::<eye::EyeResult>()?;
    m.add_class::<prepared::PyPrepared>()?;
    m.add_class::<estimate::PyErrorEstimate>()?;
    m.add_function(wrap_pyfunction!(eye::render, m)?)?;
    m.add_function(wrap_pyfunction!(eye::light_emission, m)?)?;
    m.add_function(wrap_pyfunction!(eye::irradiance, m)?)?;
    m.add_function(wrap_pyfunction!(eye::srgb_to_linear, m)?)?;
    m.add_class::<capabilities::MethodInfo>()?;
    m.add_class::<capabilities::OptionInfo>()?;
    m.add_function(wrap_pyfunction!(capabilities::capabilities, m)?)?;
    m.add_function(wrap_pyfunction!(capabilities::limits, m)?)?;
    m.add_function(wrap_pyfunction!(entry::light_frame, m)?)?;
    m.add_function(wrap_pyfunction!(entry::check_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(entry::shadow_map_from_meshes, m)?)?;
    m.add_function(wrap_pyfunction!(entry::shadow_map_from_depth, m)?)?;
    m.add_function(wrap_pyfunction!(entry::shadow_map_from_scene, m)?)?;
    m.add_function(wrap_pyfunction!(entry::sample_points, m)?)?;
    m.add_function(wrap_pyfunction!(entry::receiver_points, m)?)?;
    m.add_function(wrap_pyfunction!(gpu::gpu_available, m)?)?;
    m.add_function(wrap_pyfunction!(gpu::gpu_info, m)?)?;
    m.add(
        "GpuUnavailableError",
        m.py().get_type::<errors::GpuUnavailableError>(),
    )?;
    m.add("TooLargeError", errors::too_large_error(m.py())?)?;
    m.add_function(wrap_pyfunction!(entry::_panic_for_tests, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ENV_THREADS", crate::threads::ENV_THREADS)?;
    // `from softshadow._core import *` gives the method configs and their
    // parts, and nothing else (pyo3's `add` listed every name): the
    // package's `methods` exports them from here, so a new method's class
    // needs no line there.
    m.setattr("__all__", configs)?;
    Ok(())
}
