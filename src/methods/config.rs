//! The typed configuration of each method, as a user writes it, and its
//! resolution into what runs.
//!
//! A config holds the method's options. Options whose default depends on the
//! call (the number of occluder layers, the occluder maps' resolution, the
//! hierarchy on a backend that has none) are `None` until the config is
//! resolved against that call ([`MethodConfig::resolve`]); the resolved
//! config is what ran, and a result reports it. Every value is checked here,
//! once, when the config is built: the bindings and the Python package only
//! convert types.
//!
//! The defaults and limits below are the ones the capabilities table
//! (`capabilities.rs`) publishes.

use super::{bitmask, ssm::Precision, Method, HIERARCHY_DEFAULT_BITMASK, HIERARCHY_DEFAULT_SSM};
use crate::backend::Backend;
use crate::error::{Error, Result};
pub use crate::geom::light::check_resolution;
pub use crate::methods::shadow_mapping::config::ShadowMappingConfig;
use crate::methods::shadow_mapping::config::{check_real, Real};
use crate::methods::smoothies::Falloff;

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

/// The paper's soft shadow maps (Atty et al. 2005): additive micro-patches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SsmConfig {
    /// Occluder depth layers; `None`: 2 from meshes, the layers given from
    /// depth maps.
    pub passes: Option<u32>,
    /// Occluder maps' (W, H); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
    /// The occluder hierarchy; `None`: off (the paper has none).
    pub hierarchy: Option<bool>,
    pub precision: Precision,
}

/// Micro-patches marking light samples in a bit mask per receiver
/// (Schwarz & Stamminger 2007).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitmaskConfig {
    /// One of `bitmask::SAMPLE_COUNTS`.
    pub samples: u32,
    pub passes: Option<u32>,
    pub occluder_resolution: Option<(usize, usize)>,
    /// `None`: on where the backend has a hierarchy (the CPU), else off.
    pub hierarchy: Option<bool>,
    /// How neighbouring micro-patches meet.
    pub gaps: bitmask::Gaps,
}

/// Ray casting through a BVH of the occluder triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ExactConfig {
    pub samples: u32,
}

/// What a user picks: a method with its options, or `Auto`: without a
/// target a rule that resolves to `Ssm` (the `SsmConfig` it holds are
/// options given beside `method="auto"`, which override the rule's:
/// `ss.Auto()` holds none); with a target (`ss.Auto(error=...)`) a plan made
/// from the scene (`plan.rs`, light-view maps from meshes), elsewhere the rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MethodConfig {
    Auto(SsmConfig, super::target::Target),
    Ssm(SsmConfig),
    Bitmask(BitmaskConfig),
    Exact(ExactConfig),
    /// Scherzer 2005's practical shadow mapping (hard shadows from the
    /// light's centre or direction; `shadow_mapping/`).
    ShadowMapping(ShadowMappingConfig),
    /// Chan & Durand 2003's smoothies (`smoothies/`).
    Smoothies(SmoothiesConfig),
    /// Fernando 2005's percentage-closer soft shadows (`pcss.rs`).
    Pcss(PcssConfig),
}

/// PCSS: blocker search, penumbra estimate and PCF on the shadow map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PcssConfig {
    /// Taps per axis of the blocker search and of the filter (each box
    /// wider than this many texels is sampled by as many strata).
    pub max_taps: u32,
    /// The shadow map's (W, H); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
}

impl PcssConfig {
    pub fn new(max_taps: Option<i64>, occluder_resolution: Option<(i64, i64)>) -> Result<Self> {
        let t = max_taps.unwrap_or(crate::methods::pcss::DEFAULT_MAX_TAPS as i64);
        let max = crate::methods::pcss::MAX_TAPS as i64;
        if !(1..=max).contains(&t) {
            return Err(Error::invalid(
                "max_taps",
                format!("must be in [1, {max}], got {t}"),
            ));
        }
        Ok(PcssConfig {
            max_taps: t as u32,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
        })
    }
}

impl Default for PcssConfig {
    fn default() -> Self {
        PcssConfig {
            max_taps: crate::methods::pcss::DEFAULT_MAX_TAPS,
            occluder_resolution: None,
        }
    }
}

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
    fn given(&self) -> Vec<&'static str> {
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

/// The method names a user can pass as `method=`, in the table's order.
pub const METHOD_NAMES: [&str; 7] = [
    "ssm",
    "bitmask",
    "exact",
    "pcss",
    "smoothies",
    "shadow_mapping",
    "auto",
];

/// Light samples of `exact`: 1 to MAX_SAMPLES.
pub fn check_exact_samples(n: i64) -> Result<u32> {
    if (1..=MAX_SAMPLES as i64).contains(&n) {
        Ok(n as u32)
    } else {
        Err(Error::invalid(
            "samples",
            format!("must be in [1, {MAX_SAMPLES}], got {n}"),
        ))
    }
}

/// Light samples of `bitmask`: one of its patterns' sizes.
pub fn check_bitmask_samples(n: i64) -> Result<u32> {
    match bitmask::SAMPLE_COUNTS.iter().find(|&&c| c as i64 == n) {
        Some(&c) => Ok(c),
        None => Err(Error::invalid(
            "samples",
            format!(
                "bitmask takes one of {:?} samples, got {n}",
                bitmask::SAMPLE_COUNTS
            ),
        )),
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

/// `precision=` by name.
pub fn check_precision(name: &str) -> Result<Precision> {
    Precision::parse(name).ok_or_else(|| {
        Error::invalid(
            "precision",
            format!(
                "must be one of {:?}, got {name:?}",
                Precision::ALL.map(|p| p.name())
            ),
        )
    })
}

impl SsmConfig {
    /// Checks each given option; `None` keeps the default.
    pub fn new(
        passes: Option<i64>,
        occluder_resolution: Option<(i64, i64)>,
        hierarchy: Option<bool>,
        precision: Option<&str>,
    ) -> Result<Self> {
        Ok(SsmConfig {
            passes: passes.map(check_passes).transpose()?,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
            hierarchy,
            precision: precision
                .map(check_precision)
                .transpose()?
                .unwrap_or_default(),
        })
    }
}

impl BitmaskConfig {
    pub fn new(
        samples: Option<i64>,
        passes: Option<i64>,
        occluder_resolution: Option<(i64, i64)>,
        hierarchy: Option<bool>,
        gaps: Option<&str>,
    ) -> Result<Self> {
        let gaps = match gaps {
            None => bitmask::Gaps::default(),
            Some(g) => bitmask::Gaps::parse(g).ok_or_else(|| {
                let names: Vec<&str> = bitmask::Gaps::ALL.iter().map(|g| g.name()).collect();
                Error::invalid("gaps", format!("must be one of {names:?}, got {g:?}"))
            })?,
        };
        Ok(BitmaskConfig {
            gaps,
            samples: samples
                .map(check_bitmask_samples)
                .transpose()?
                .unwrap_or(DEFAULT_SAMPLES),
            passes: passes.map(check_passes).transpose()?,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
            hierarchy,
        })
    }
}

impl Default for BitmaskConfig {
    fn default() -> Self {
        BitmaskConfig {
            samples: DEFAULT_SAMPLES,
            passes: None,
            occluder_resolution: None,
            hierarchy: None,
            gaps: Default::default(),
        }
    }
}

impl ExactConfig {
    pub fn new(samples: Option<i64>) -> Result<Self> {
        Ok(ExactConfig {
            samples: samples
                .map(check_exact_samples)
                .transpose()?
                .unwrap_or(DEFAULT_SAMPLES),
        })
    }
}

impl Default for ExactConfig {
    fn default() -> Self {
        ExactConfig {
            samples: DEFAULT_SAMPLES,
        }
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

/// What `method="auto"` runs at output `resolution` (W, H): the paper's
/// method with two passes and occluder maps at a quarter of the output's
/// resolution, at least 64 (never more than the output's).
///
/// The rule comes from the study (`python -m softshadow.experiments.study`,
/// docs/study/study.md): on its four scenes at 256², this is the point of the
/// accuracy-time plane where softshadow is furthest ahead of Mitsuba's
/// `ray_test` at equal error (4.4-7.9x faster, errors 0.030-0.037); finer
/// occluder maps cost 2.5-8x more for at most 0.005 less error. Below 64
/// texels an occluder map loses small occluders.
pub fn auto_rule(resolution: (usize, usize)) -> SsmConfig {
    let quarter = |n: usize| n.min((n / 4).max(64));
    SsmConfig {
        passes: Some(DEFAULT_PASSES),
        occluder_resolution: Some((quarter(resolution.0), quarter(resolution.1))),
        hierarchy: None,
        precision: Precision::F32,
    }
}

/// Options shared by the occluder-map methods, resolved for a call.
fn resolve_maps(
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

impl MethodConfig {
    /// The config named `name` with the loose options given: each must apply
    /// to that method.
    pub fn from_name(name: &str, o: &LooseOptions) -> Result<Self> {
        let refuse = |opt: &str, applies: &str| {
            Err(Error::invalid(
                opt,
                format!("applies to {applies}, not to {name:?}"),
            ))
        };
        let c = match name {
            "ssm" => {
                if o.samples.is_some() {
                    return refuse("samples", "the sampling methods (\"bitmask\", \"exact\")");
                }
                MethodConfig::Ssm(SsmConfig::new(
                    o.passes,
                    o.occluder_resolution,
                    o.hierarchy,
                    o.precision,
                )?)
            }
            "bitmask" => {
                if o.precision.is_some() {
                    return refuse(
                        "precision",
                        "\"ssm\" (sums of occlusions); the other methods count samples exactly",
                    );
                }
                MethodConfig::Bitmask(BitmaskConfig::new(
                    o.samples,
                    o.passes,
                    o.occluder_resolution,
                    o.hierarchy,
                    None,
                )?)
            }
            "exact" => {
                // `passes` beside "exact" is accepted and has no effect (the
                // string form always allowed it: it reads no layers).
                if let Some(p) = o.passes {
                    check_passes(p)?;
                }
                for (given, opt) in [
                    (o.occluder_resolution.is_some(), "occluder_resolution"),
                    (o.hierarchy.is_some(), "hierarchy"),
                ] {
                    if given {
                        return refuse(
                            opt,
                            "the occluder-map methods (\"ssm\", \"bitmask\"); \"exact\" traces the occluder triangles",
                        );
                    }
                }
                if o.precision.is_some() {
                    return refuse(
                        "precision",
                        "\"ssm\" (sums of occlusions); the other methods count samples exactly",
                    );
                }
                MethodConfig::Exact(ExactConfig::new(o.samples)?)
            }
            "auto" => {
                // The rule's choice is "ssm": its options given beside
                // "auto" replace the rule's.
                if o.samples.is_some() {
                    return refuse("samples", "the sampling methods (\"bitmask\", \"exact\")");
                }
                MethodConfig::Auto(
                    SsmConfig::new(o.passes, o.occluder_resolution, o.hierarchy, o.precision)?,
                    Default::default(),
                )
            }
            "pcss" => {
                if let Some(opt) = o.given().into_iter().find(|o| *o != "occluder_resolution") {
                    return refuse(opt, "other methods; give PCSS(...) its own options");
                }
                MethodConfig::Pcss(PcssConfig::new(None, o.occluder_resolution)?)
            }
            "smoothies" => {
                if let Some(opt) = o.given().into_iter().find(|o| *o != "occluder_resolution") {
                    return refuse(opt, "other methods; give Smoothies(...) its own options");
                }
                MethodConfig::Smoothies(SmoothiesConfig::new(
                    None,
                    None,
                    None,
                    o.occluder_resolution,
                )?)
            }
            "shadow_mapping" => {
                if let Some(opt) = o.given().first() {
                    return refuse(
                        opt,
                        "the soft shadow map methods; give ShadowMapping(...) its own options",
                    );
                }
                MethodConfig::ShadowMapping(ShadowMappingConfig::default())
            }
            other => {
                return Err(Error::invalid(
                    "method",
                    format!("unknown method {other:?}; available: {METHOD_NAMES:?}"),
                ))
            }
        };
        Ok(c)
    }

    /// A typed config passed with loose options too: refused (one place says
    /// each option).
    pub fn refuse_loose(o: &LooseOptions) -> Result<()> {
        match o.given().first() {
            None => Ok(()),
            Some(opt) => Err(Error::invalid(
                *opt,
                "give it inside the method config (for example method=Bitmask(samples=64)), \
                 not beside it",
            )),
        }
    }

    /// The name a user passes as `method=`.
    pub fn name(&self) -> &'static str {
        match self {
            MethodConfig::Auto(..) => "auto",
            MethodConfig::Ssm(_) => "ssm",
            MethodConfig::Bitmask(_) => "bitmask",
            MethodConfig::Exact(_) => "exact",
            MethodConfig::ShadowMapping(_) => "shadow_mapping",
            MethodConfig::Smoothies(_) => "smoothies",
            MethodConfig::Pcss(_) => "pcss",
        }
    }

    /// The config that runs for `ctx`: "auto" replaced by its rule, every
    /// call-dependent default filled in, backend restrictions checked.
    pub fn resolve(&self, ctx: &CallContext) -> Result<MethodConfig> {
        Ok(match *self {
            MethodConfig::Auto(given, _) => {
                let rule = match ctx.depth_layers {
                    // From depth maps the layers and their resolution are given.
                    Some(_) => SsmConfig::default(),
                    None => auto_rule(ctx.resolution),
                };
                let ssm = SsmConfig {
                    passes: given.passes.or(rule.passes),
                    occluder_resolution: given.occluder_resolution.or(rule.occluder_resolution),
                    hierarchy: given.hierarchy.or(rule.hierarchy),
                    precision: given.precision,
                };
                return MethodConfig::Ssm(ssm).resolve(ctx);
            }
            MethodConfig::Ssm(c) => {
                if ctx.backend == Backend::Gpu && c.precision != Precision::F32 {
                    return Err(Error::invalid(
                        "precision",
                        format!(
                            "the GPU backend sums in \"f32\" only, got {:?}; use backend=\"cpu\"",
                            c.precision.name()
                        ),
                    ));
                }
                let (passes, occ, hierarchy) = resolve_maps(
                    c.passes,
                    c.occluder_resolution,
                    c.hierarchy,
                    HIERARCHY_DEFAULT_SSM,
                    ctx,
                )?;
                MethodConfig::Ssm(SsmConfig {
                    passes: Some(passes),
                    occluder_resolution: Some(occ),
                    hierarchy: Some(hierarchy),
                    precision: c.precision,
                })
            }
            MethodConfig::Bitmask(c) => {
                let (passes, occ, hierarchy) = resolve_maps(
                    c.passes,
                    c.occluder_resolution,
                    c.hierarchy,
                    HIERARCHY_DEFAULT_BITMASK,
                    ctx,
                )?;
                MethodConfig::Bitmask(BitmaskConfig {
                    samples: c.samples,
                    gaps: c.gaps,
                    passes: Some(passes),
                    occluder_resolution: Some(occ),
                    hierarchy: Some(hierarchy),
                })
            }
            MethodConfig::Exact(c) => {
                if ctx.depth_layers.is_some() {
                    return Err(Error::invalid(
                        "method",
                        "\"exact\" traces the occluder triangles, which depth maps do not have; \
                         use soft_shadow_map with meshes",
                    ));
                }
                MethodConfig::Exact(c)
            }
            MethodConfig::ShadowMapping(c) => {
                if !ctx.eye {
                    return Err(Error::invalid(
                        "method",
                        "ShadowMapping renders the eye view (ss.render): its map is focused, \
                         warped and blurred for a camera; in the light view use method=\"ssm\" \
                         or \"exact\" with a point light for hard shadows",
                    ));
                }
                if ctx.depth_layers.is_some() {
                    return Err(Error::invalid(
                        "method",
                        "ShadowMapping rasterizes its own map of the meshes; depth maps are not enough",
                    ));
                }
                MethodConfig::ShadowMapping(c)
            }
            MethodConfig::Smoothies(c) => {
                if ctx.depth_layers.is_some() {
                    return Err(Error::invalid(
                        "method",
                        "Smoothies find the occluders' silhouette edges, which depth maps do not \
                         have; use soft_shadow_map with meshes",
                    ));
                }
                MethodConfig::Smoothies(SmoothiesConfig {
                    occluder_resolution: Some(c.occluder_resolution.unwrap_or(ctx.resolution)),
                    ..c
                })
            }
            MethodConfig::Pcss(c) => {
                // From depth maps: the front layer the user gave.
                let (_, occ, _) = resolve_maps(
                    Some(1),
                    c.occluder_resolution,
                    Some(false),
                    false,
                    &CallContext {
                        depth_layers: ctx.depth_layers.map(|(_, shape)| (1, shape)),
                        ..*ctx
                    },
                )?;
                MethodConfig::Pcss(PcssConfig {
                    occluder_resolution: Some(occ),
                    ..c
                })
            }
        })
    }

    /// The kernel of a config; resolve it first for the backend's defaults.
    pub fn kernel(&self) -> Method {
        match *self {
            MethodConfig::Ssm(c) => Method::Ssm {
                hierarchy: c.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
                precision: c.precision,
            },
            MethodConfig::Bitmask(c) => Method::Bitmask {
                samples: c.samples,
                hierarchy: c.hierarchy.unwrap_or(HIERARCHY_DEFAULT_BITMASK),
                gaps: c.gaps,
            },
            MethodConfig::Exact(c) => Method::Exact { samples: c.samples },
            // What "auto" always resolves to.
            MethodConfig::Auto(c, _) => Method::Ssm {
                hierarchy: c.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
                precision: c.precision,
            },
            MethodConfig::ShadowMapping(c) => Method::ShadowMapping(c),
            MethodConfig::Smoothies(c) => Method::Smoothies {
                width: c.width,
                falloff: c.falloff,
            },
            MethodConfig::Pcss(c) => Method::Pcss {
                max_taps: c.max_taps,
            },
        }
    }

    /// Occluder layers of a resolved config (0 for methods that read none).
    pub fn passes(&self) -> u32 {
        match *self {
            MethodConfig::Ssm(c) => c.passes.unwrap_or(DEFAULT_PASSES),
            MethodConfig::Bitmask(c) => c.passes.unwrap_or(DEFAULT_PASSES),
            // The shadow map: the front layer.
            MethodConfig::Smoothies(_) | MethodConfig::Pcss(_) => 1,
            MethodConfig::Exact(_) | MethodConfig::Auto(..) | MethodConfig::ShadowMapping(_) => 0,
        }
    }

    /// Occluder maps' (W, H) of a resolved config (None for methods that
    /// read no maps).
    pub fn occluder_resolution(&self) -> Option<(usize, usize)> {
        match *self {
            MethodConfig::Ssm(c) => c.occluder_resolution,
            MethodConfig::Bitmask(c) => c.occluder_resolution,
            MethodConfig::Smoothies(c) => c.occluder_resolution,
            MethodConfig::Pcss(c) => c.occluder_resolution,
            MethodConfig::Exact(_) | MethodConfig::Auto(..) | MethodConfig::ShadowMapping(_) => {
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cpu(resolution: (usize, usize)) -> CallContext {
        CallContext {
            backend: Backend::Cpu,
            resolution,
            depth_layers: None,
            eye: false,
        }
    }

    #[test]
    fn auto_is_ssm_with_quarter_occluder_maps_at_least_64() {
        let r = MethodConfig::Auto(SsmConfig::default(), Default::default())
            .resolve(&cpu((512, 100)))
            .unwrap();
        assert_eq!(r.occluder_resolution(), Some((128, 64)));
        assert_eq!(r.passes(), 2);
        let r = MethodConfig::Auto(SsmConfig::default(), Default::default())
            .resolve(&cpu((40, 40)))
            .unwrap();
        assert_eq!(r.occluder_resolution(), Some((40, 40)));
    }

    #[test]
    fn defaults_depend_on_the_backend_and_the_entry() {
        let b = MethodConfig::Bitmask(BitmaskConfig::default());
        assert_eq!(
            b.resolve(&cpu((8, 8))).unwrap().kernel(),
            Method::Bitmask {
                samples: 256,
                hierarchy: true,
                gaps: bitmask::Gaps::Closed,
            }
        );
        let gpu = CallContext {
            backend: Backend::Gpu,
            ..cpu((8, 8))
        };
        assert_eq!(
            b.resolve(&gpu).unwrap().kernel(),
            Method::Bitmask {
                samples: 256,
                hierarchy: false,
                gaps: bitmask::Gaps::Closed,
            }
        );
        let depth = CallContext {
            depth_layers: Some((1, (4, 4))),
            ..cpu((8, 8))
        };
        let r = b.resolve(&depth).unwrap();
        assert_eq!((r.passes(), r.occluder_resolution()), (1, Some((4, 4))));
        let three =
            MethodConfig::Bitmask(BitmaskConfig::new(None, Some(3), None, None, None).unwrap());
        assert!(
            matches!(three.resolve(&depth), Err(Error::InvalidArgument { ref arg, .. }) if arg == "passes")
        );
    }

    #[test]
    fn options_that_do_not_apply_are_refused_by_name() {
        let o = LooseOptions {
            samples: Some(64),
            ..Default::default()
        };
        let e = MethodConfig::from_name("ssm", &o).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "samples"));
        let o = LooseOptions {
            hierarchy: Some(true),
            ..Default::default()
        };
        let e = MethodConfig::from_name("exact", &o).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "hierarchy"));
        assert!(MethodConfig::refuse_loose(&o).is_err());
    }
}
