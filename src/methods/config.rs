//! What the methods' configs share: the call a config is resolved against
//! (`CallContext`), the string form's loose options (`LooseOptions`), the
//! trait each config implements in its method's module (`MethodSpec`), the
//! resolution of the occluder-map options (`resolve_maps`), the shared
//! checks, option rows and limits.
//!
//! A config holds the method's options. Options whose default depends on the
//! call (the number of occluder layers, the occluder maps' resolution, the
//! hierarchy on a backend that has none) are `None` until the config is
//! resolved against that call (`MethodConfig::resolve`); the resolved
//! config is what ran, and a result reports it. Every value is checked by
//! the config's constructor, once, when the config is built: the bindings
//! and the Python package only convert types.
//!
//! This file names no method: each method's config lives in its own module
//! (`ssm.rs`, `bitmask.rs`, `exact.rs`, `pcss.rs`, `smoothies/config.rs`,
//! `shadow_mapping/config.rs`, `auto_config.rs`), which imports this one,
//! and the registry (`mod.rs`) lists them once. The defaults and limits
//! below are the ones the capabilities table publishes.

use super::info::{Kind, MethodInfo, OptionInfo, Value};
use crate::backend::Backend;
use crate::error::{Error, Result};
pub use crate::geom::light::check_resolution;
use crate::geom::light::MAX_TEXELS;

/// Default light samples per receiver for the sampling methods (a 16x16
/// stratification).
pub const DEFAULT_SAMPLES: u32 = 256;
/// The most light samples per receiver `exact` accepts.
pub const MAX_SAMPLES: u32 = 1 << 16;
/// The most occluder depth layers we peel.
pub const MAX_PASSES: u32 = 8;
/// Occluder layers taken from meshes when `passes` is not given: front and
/// back (§3.5 of the paper).
pub const DEFAULT_PASSES: u32 = 2;

/// Options given loosely by name (the string form `method="bitmask",
/// samples=64`); each must apply to the named method.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LooseOptions<'a> {
    pub passes: Option<i64>,
    pub samples: Option<i64>,
    pub occluder_resolution: Option<(i64, i64)>,
    pub hierarchy: Option<bool>,
    pub precision: Option<&'a str>,
}

impl LooseOptions<'_> {
    /// The names of the options given.
    pub fn given(&self) -> Vec<&'static str> {
        let mut v = vec![];
        if self.passes.is_some() {
            v.push("passes");
        }
        if self.samples.is_some() {
            v.push("samples");
        }
        if self.occluder_resolution.is_some() {
            v.push("occluder_resolution");
        }
        if self.hierarchy.is_some() {
            v.push("hierarchy");
        }
        if self.precision.is_some() {
            v.push("precision");
        }
        v
    }
}

/// How many occluder depth layers are taken: 1, the front; 2, front and back
/// (§3.5); more, front, the next layers by depth peeling, and back.
pub fn check_passes(passes: i64) -> Result<u32> {
    if (1..=MAX_PASSES as i64).contains(&passes) {
        Ok(passes as u32)
    } else {
        Err(Error::invalid(
            "passes",
            format!(
                "must be 1 (front layer), 2 (front and back) or up to {MAX_PASSES} (front, peeled layers, back), got {passes}"
            ),
        ))
    }
}

/// The call a config is resolved against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CallContext {
    /// The backend that will run it.
    pub backend: Backend,
    /// The output map's (W, H).
    pub resolution: (usize, usize),
    /// From depth maps: how many occluder layers the user gave and their
    /// (W, H). `None`: from meshes (the pipeline makes the layers).
    pub depth_layers: Option<(u32, (usize, usize))>,
    /// Whether the call has a camera (the eye view).
    pub eye: bool,
}

/// Options shared by the occluder-map methods, resolved for a call.
pub fn resolve_maps(
    passes: Option<u32>,
    occluder_resolution: Option<(usize, usize)>,
    hierarchy: Option<bool>,
    default_hierarchy: bool,
    ctx: &CallContext,
) -> Result<(u32, (usize, usize), bool)> {
    let hierarchy = match (hierarchy, ctx.backend) {
        (Some(true), Backend::Gpu) => {
            return Err(Error::invalid(
                "hierarchy",
                "the GPU backend has no occluder hierarchy yet; use backend=\"cpu\"",
            ))
        }
        (Some(h), _) => h,
        // The GPU kernels have no hierarchy: off there by default.
        (None, Backend::Gpu) => false,
        (None, Backend::Cpu) => default_hierarchy,
    };
    match ctx.depth_layers {
        None => Ok((
            passes.unwrap_or(DEFAULT_PASSES),
            occluder_resolution.unwrap_or(ctx.resolution),
            hierarchy,
        )),
        Some((layers, shape)) => {
            if let Some(p) = passes.filter(|&p| p != layers) {
                return Err(Error::invalid(
                    "passes",
                    format!(
                        "the depth maps given hold {layers} occluder layer(s), not {p} \
                         (occluder_depth, and occluder_depth_back for 2)"
                    ),
                ));
            }
            if let Some(r) = occluder_resolution.filter(|&r| r != shape) {
                return Err(Error::invalid(
                    "occluder_resolution",
                    format!(
                        "the occluder maps given are {}x{}, not {}x{}",
                        shape.0, shape.1, r.0, r.1
                    ),
                ));
            }
            Ok((layers, shape, hierarchy))
        }
    }
}

/// One method's config as the registry (`registry.rs`, listed in `mod.rs`)
/// reads it: its name, its config from the string form, its resolution for
/// a call and the occluder maps it reads, and its row of `capabilities()`.
/// Implemented in the method's own module. What a resolution gives is an
/// associated type, not `MethodConfig`, so that no method module names the
/// registry that names it (the registry makes `From<Config> for
/// MethodConfig` for each config it lists).
pub trait MethodSpec: Copy {
    /// The name a user passes as `method=`.
    const NAME: &'static str;
    /// What the config resolves to: itself (`auto`: the `SsmConfig` its
    /// rule picks).
    type Resolved;
    /// The config of the string form (`method="bitmask", samples=64`): each
    /// loose option given must apply to the method; `refuse(option,
    /// applies_to)` says one does not.
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self>;
    /// The config that runs for `ctx`: every call-dependent default filled
    /// in, backend restrictions checked ("auto" replaced by its rule).
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved>;
    /// The kernel it runs (`kernel::Kernel`, in the method's module).
    type Kernel;
    /// The kernel of the config; of a resolved one, what ran (an unresolved
    /// one's call-dependent options take their CPU defaults).
    fn kernel(&self) -> Self::Kernel;
    /// Occluder layers of a resolved config (0 for methods that read none).
    fn passes(&self) -> u32 {
        0
    }
    /// Occluder maps' (W, H) of a resolved config (None for methods that
    /// read no maps).
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        None
    }
    /// The method's row of `capabilities()`: its options, defaults,
    /// limits, backends and what it reads.
    fn info() -> MethodInfo;
}

/// The option `passes` of the occluder-map methods.
pub fn passes_option() -> OptionInfo {
    OptionInfo {
        name: "passes",
        kind: Kind::Int {
            min: 1,
            max: MAX_PASSES as i64,
        },
        default: Value::Resolved,
        default_doc: "2 (front and back) from meshes; the layers given from depth maps",
        doc: "occluder depth layers: 1, the front; 2, front and back (paper §3.5); 3 to 8, \
              front, passes - 2 layers found by depth peeling, and back",
        restricted_on: vec![],
    }
}

/// The option `occluder_resolution` of the map methods.
pub fn occluder_resolution_option() -> OptionInfo {
    OptionInfo {
        name: "occluder_resolution",
        kind: Kind::Resolution {
            max_texels: MAX_TEXELS as i64,
        },
        default: Value::Resolved,
        default_doc: "the output's resolution; from depth maps, the occluder maps' shape",
        doc: "resolution of the occluder maps (same extent as the output): coarser maps \
              cost less, their error is the discretization of paper §4.1.1",
        restricted_on: vec![],
    }
}

/// The option `hierarchy` of the occluder-map methods.
pub fn hierarchy_option(default_on: bool) -> OptionInfo {
    OptionInfo {
        name: "hierarchy",
        kind: Kind::Bool,
        default: Value::Resolved,
        default_doc: if default_on {
            "on on the CPU; off on the GPU, which has no hierarchy"
        } else {
            "off (the paper's method, reproduced as published)"
        },
        doc: "read the occluder maps through a min/max pyramid: each 8x8 tile of receivers \
              reads the coarsest level whose texels cover at most 3% of the light's width",
        restricted_on: vec![(Backend::Gpu, vec![Value::Bool(false)])],
    }
}

/// `precision` applies to the sums of `ssm` only.
pub const PRECISION_SSM_ONLY: &str =
    "\"ssm\" (sums of occlusions); the other methods count samples exactly";
/// `samples` applies to the sampling methods only.
pub const SAMPLES_ONLY: &str = "the sampling methods (\"bitmask\", \"exact\")";
