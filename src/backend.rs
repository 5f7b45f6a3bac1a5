//! The backends a call can run on: the CPU stages (rayon) or their GPU
//! twins (`crate::gpu`, wgpu compute), and what a user asks for. A leaf:
//! the configs resolve against a backend, the API picks one (`api.rs`).

use crate::error::{Error, Result};

/// A backend that runs shadow maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Backend {
    /// All cores (rayon); always built.
    Cpu,
    /// wgpu compute (cargo feature `gpu`).
    Gpu,
}

/// What a user asks for: a backend, or `Auto`: the GPU when a real
/// (non-software) adapter is present and runs the call, else the CPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BackendChoice {
    Cpu,
    Gpu,
    Auto,
}

impl Backend {
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Gpu => "gpu",
        }
    }

    /// The backends this build has.
    pub fn built() -> &'static [Backend] {
        if cfg!(feature = "gpu") {
            &[Backend::Cpu, Backend::Gpu]
        } else {
            &[Backend::Cpu]
        }
    }
}

impl BackendChoice {
    /// `backend=` by name: "cpu", "gpu" or "auto".
    pub fn parse(name: &str) -> Result<BackendChoice> {
        match name {
            "cpu" => Ok(BackendChoice::Cpu),
            "gpu" => Ok(BackendChoice::Gpu),
            "auto" => Ok(BackendChoice::Auto),
            other => Err(Error::invalid(
                "backend",
                format!("must be one of \"cpu\", \"gpu\", \"auto\", got {other:?}"),
            )),
        }
    }
}

/// What a GPU request gets from a build without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
pub fn not_built() -> Error {
    Error::gpu_unavailable("this build of softshadow has no GPU backend (cargo feature `gpu`)")
}

/// The largest map side on the GPU: fixed-point coordinates ((side + 2
/// guard bands) x 256) must fit in i32 for the shader's edge functions,
/// texel offsets below 2^16 keep the depth plane's limb products exact, and
/// a row's statistics (one invocation a row) stay within lavapipe's 65535
/// loop iterations.
pub const GPU_MAX_SIDE: usize = 1 << 14;
