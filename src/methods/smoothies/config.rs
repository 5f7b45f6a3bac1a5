//! The typed config of Smoothies (`SmoothiesConfig`), as a user writes it:
//! its checks, defaults and its `MethodSpec` (name, string form,
//! resolution, capabilities row).

use super::method::SmoothiesKernel;
use super::Falloff;
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::methods::config::{check_resolution, occluder_resolution_option};
use crate::methods::config::{CallContext, LooseOptions, MethodSpec};
use crate::methods::info::{Kind, MethodInfo, OptionInfo, Value};
use crate::methods::kernel::Kernel;
use crate::methods::keywords::{resolution, KeywordForm, Keywords};
use crate::methods::shadow_mapping::config::{check_real, Real};

/// Smoothies (Chan & Durand 2003): fake soft shadows from the hard shadow
/// map and silhouette-edge smoothies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SmoothiesConfig {
    /// The smoothies' width, dimensionless: 1 spans the whole penumbra of
    /// the light's size for blockers at the median silhouette depth.
    pub width: Real,
    pub falloff: Falloff,
    /// The shadow map's (W, H); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
}

/// Measured by `benchmarks/bench_shadow_mapping.py`
/// (docs/benchmarks/shadow_mapping.md): against 256-sample `exact` on the
/// four eye-view scenes, width 0.5 is within 0.0006 of the best of
/// 0.25-4 on each, width 1 is 0.0003-0.015 worse. Smoothies darken only
/// outside the hard shadow, where the true penumbra has half its width.
pub const DEFAULT_SMOOTHIE_WIDTH: f64 = 0.5;
pub const MAX_SMOOTHIE_WIDTH: f64 = 16.0;
/// The lookups Smoothies offers: the paper's 2x2 tent.
pub const SMOOTHIE_FILTERS: [&str; 1] = ["bilinear"];

impl SmoothiesConfig {
    pub fn new(
        width: Option<f64>,
        falloff: Option<&str>,
        filter: Option<&str>,
        occluder_resolution: Option<(i64, i64)>,
    ) -> Result<Self> {
        if let Some(f) = filter.filter(|f| !SMOOTHIE_FILTERS.contains(f)) {
            return Err(Error::invalid(
                "filter",
                format!("must be one of {SMOOTHIE_FILTERS:?} (the paper's 2x2 tent), got {f:?}"),
            ));
        }
        let falloff = match falloff {
            None => Falloff::Linear,
            Some(f) => Falloff::parse(f).ok_or_else(|| {
                Error::invalid(
                    "falloff",
                    format!(
                        "must be one of {:?}, got {f:?}",
                        Falloff::ALL.map(|f| f.name())
                    ),
                )
            })?,
        };
        Ok(SmoothiesConfig {
            width: check_real(
                "width",
                width.unwrap_or(DEFAULT_SMOOTHIE_WIDTH),
                0.0,
                MAX_SMOOTHIE_WIDTH,
                "a factor of the light-matched width",
            )
            .and_then(|w| {
                if w.0 > 0.0 {
                    Ok(w)
                } else {
                    Err(Error::invalid(
                        "width",
                        "must be > 0 (0 would be the hard shadow map)",
                    ))
                }
            })?,
            falloff,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
        })
    }
}

impl Default for SmoothiesConfig {
    fn default() -> Self {
        SmoothiesConfig {
            width: Real(DEFAULT_SMOOTHIE_WIDTH),
            falloff: Falloff::Linear,
            occluder_resolution: None,
        }
    }
}

impl KeywordForm for SmoothiesConfig {
    fn from_keywords(k: &Keywords) -> Result<Self> {
        SmoothiesConfig::new(
            k.float("width")?,
            k.str("falloff")?,
            k.str("filter")?,
            k.resolution("occluder_resolution")?,
        )
    }
    fn keywords(&self) -> Vec<(&'static str, Value)> {
        vec![
            ("width", Value::Float(self.width.0)),
            ("falloff", Value::Str(self.falloff.name())),
            ("filter", Value::Str(SMOOTHIE_FILTERS[0])),
            ("occluder_resolution", resolution(self.occluder_resolution)),
        ]
    }
}

impl MethodSpec for SmoothiesConfig {
    const NAME: &'static str = "smoothies";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if let Some(opt) = o.given().into_iter().find(|o| *o != "occluder_resolution") {
            return Err(refuse(
                opt,
                "other methods; give Smoothies(...) its own options",
            ));
        }
        SmoothiesConfig::new(None, None, None, o.occluder_resolution)
    }
    type Resolved = Self;
    type Kernel = SmoothiesKernel;
    fn kernel(&self) -> SmoothiesKernel {
        SmoothiesKernel {
            width: self.width,
            falloff: self.falloff,
        }
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        if ctx.depth_layers.is_some() {
            return Err(Error::invalid(
                "method",
                "Smoothies find the occluders' silhouette edges, which depth maps do not \
                 have; use soft_shadow_map with meshes",
            ));
        }
        Ok(SmoothiesConfig {
            occluder_resolution: Some(self.occluder_resolution.unwrap_or(ctx.resolution)),
            ..self
        })
    }
    // The shadow map: the front layer.
    fn passes(&self) -> u32 {
        1
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "smoothies",
            config: "Smoothies",
            summary: "Fake soft shadows (Chan & Durand 2003): the hard shadow map's umbra and an \
                      outer penumbra from smoothies on the occluders' silhouette edges, their \
                      alpha remapped by 1/(1 - b/r)",
            // The kernel's (`Kernel::READS`).
            reads: SmoothiesKernel::READS.to_vec(),
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "width",
                    kind: Kind::Float,
                    default: Value::Float(DEFAULT_SMOOTHIE_WIDTH),
                    default_doc:
                        "0.5, measured against exact on the eye scenes (1.0 is the penumbra of \
                         the light's size for blockers at the median silhouette depth)",
                    doc: "the smoothies' width in the light's image plane, as a factor of the \
                          light-matched width, in (0, 16]",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "falloff",
                    kind: Kind::Choice(Falloff::ALL.iter().map(|f| f.name()).collect()),
                    default: Value::Str("linear"),
                    default_doc: "linear",
                    doc:
                        "the penumbra's profile: linear alpha, or the sinusoidal (1 - cos(pi v))/2",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "filter",
                    kind: Kind::Choice(SMOOTHIE_FILTERS.to_vec()),
                    default: Value::Str("bilinear"),
                    default_doc: "bilinear",
                    doc: "the lookup: the paper's 2x2 tent over the shadow map and smoothie buffer",
                    restricted_on: vec![],
                },
                occluder_resolution_option(),
            ],
        }
    }
}
