//! What the GPU backend refuses before any device work, shared by its
//! stages: maps larger than its fixed-point coordinates allow, buffers
//! larger than one binding, and point lights, which have no GPU kernel.
//! (A method's options: its kernel's `GpuKernel::check`.)

use super::context::Gpu;
use crate::error::{Error, Result};

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

/// Refuses a buffer of the eye view that one binding cannot hold.
pub(super) fn fits(g: &Gpu, arg: &str, bytes: u64) -> Result<()> {
    if bytes > g.max_storage_binding {
        return Err(Error::too_large(
            arg,
            format!(
                "the eye view needs {bytes} bytes in one GPU buffer; the device binds at most {}; \
                 use backend=\"cpu\"",
                g.max_storage_binding
            ),
        ));
    }
    Ok(())
}
