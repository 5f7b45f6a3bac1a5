//! What the GPU backend refuses before any device work, shared by its
//! stages: a method it has no kernel for, maps larger than its fixed-point
//! coordinates allow, and point lights, which have no GPU kernel.

use crate::error::{Error, Result};
use crate::methods::Method;

/// The largest map side on the GPU (`crate::backend::GPU_MAX_SIDE`).
pub(crate) const MAX_SIDE: usize = crate::backend::GPU_MAX_SIDE;

pub fn check_side(arg: &str, g: (usize, usize)) -> Result<()> {
    if g.0 > MAX_SIDE || g.1 > MAX_SIDE {
        return Err(Error::too_large(
            arg,
            format!(
                "{}x{} exceeds the GPU backend's largest side {MAX_SIDE}; use backend=\"cpu\"",
                g.0, g.1
            ),
        ));
    }
    Ok(())
}

/// A point light (size 0) has no GPU kernel: its hard shadow map is the
/// CPU's (`point_light.rs`).
pub(crate) fn point_light_on_gpu(arg: &str) -> Error {
    Error::invalid(
        arg,
        "a point light (size 0) runs on the CPU backend only; use backend=\"cpu\"",
    )
}

/// Refuses a method the GPU has no kernel for. `exact` (exact.rs), PCSS
/// (pcss.rs) and Smoothies (smoothies.rs) have kernels of their own; the
/// gather methods are refused by the variant they would run
/// (`gather::check_method`).
pub(crate) fn check_method(method: Method) -> Result<()> {
    if method.traces() || matches!(method, Method::Pcss { .. }) {
        return Ok(());
    }
    super::gather::check_method(method)
}
