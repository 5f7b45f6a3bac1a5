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
//! Each config describes itself once (`MethodSpec`): its name, its config
//! from the string form's loose options, its resolution for a call, its
//! kernel, the maps it reads and its row of the capabilities table; the
//! registry (`method_configs!`) lists the configs once and makes the
//! `MethodConfig` enum and its dispatch from that list. A new method is its
//! config, its `MethodSpec` and one line of the registry here, beside its
//! kernel (`registry.rs`), its bindings class (`config_class!`) and its GPU
//! stage. The defaults and limits below are the ones the capabilities table
//! publishes.

use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::Input;
use super::{bitmask, ssm::Precision, Method, HIERARCHY_DEFAULT_BITMASK, HIERARCHY_DEFAULT_SSM};
use crate::backend::Backend;
use crate::error::{Error, Result};
pub use crate::geom::light::check_resolution;
use crate::geom::light::MAX_TEXELS;
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

/// What `ss.Auto` holds: the options given beside `method="auto"` (they
/// override the rule's: `ss.Auto()` holds none) and the target. Without a
/// target a rule that resolves to `Ssm`; with one (`ss.Auto(error=...)`) a
/// plan made from the scene (`crate::auto`), elsewhere the rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct AutoConfig {
    pub given: SsmConfig,
    pub target: super::target::Target,
}

/// One method's config as the registry (`method_configs!` below) reads it:
/// its name, its config from the string form, its resolution for a call,
/// its kernel and the occluder maps it reads.
pub trait MethodSpec: Copy {
    /// The name a user passes as `method=`.
    const NAME: &'static str;
    /// The config of the string form (`method="bitmask", samples=64`): each
    /// loose option given must apply to the method; `refuse(option,
    /// applies_to)` says one does not.
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self>;
    /// The config that runs for `ctx`: every call-dependent default filled
    /// in, backend restrictions checked ("auto" replaced by its rule).
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig>;
    /// The kernel of a config; resolve it first for the backend's defaults.
    fn kernel(&self) -> Method;
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

/// The registry of method configs: one line a method makes its
/// `MethodConfig` variant, its name in `METHOD_NAMES` and the dispatch of
/// every `MethodConfig` method to its `MethodSpec`.
macro_rules! method_configs {
    ($($(#[doc = $doc:literal])* $variant:ident($config:ty),)*) => {
        /// What a user picks: a method with its options, or `Auto` (see
        /// `AutoConfig`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum MethodConfig {
            $($(#[doc = $doc])* $variant($config),)*
        }

        /// The method names a user can pass as `method=`, in the table's order.
        pub const METHOD_NAMES: &[&str] = &[$(<$config as MethodSpec>::NAME),*];

        impl MethodConfig {
            /// The config named `name` with the loose options given: each
            /// must apply to that method.
            pub fn from_name(name: &str, o: &LooseOptions) -> Result<Self> {
                let refuse = |opt: &str, applies: &str| {
                    Error::invalid(opt, format!("applies to {applies}, not to {name:?}"))
                };
                $(if name == <$config as MethodSpec>::NAME {
                    return Ok(MethodConfig::$variant(<$config>::from_loose(o, &refuse)?));
                })*
                Err(Error::invalid(
                    "method",
                    format!("unknown method {name:?}; available: {METHOD_NAMES:?}"),
                ))
            }

            /// The name a user passes as `method=`.
            pub fn name(&self) -> &'static str {
                match self {
                    $(MethodConfig::$variant(_) => <$config as MethodSpec>::NAME,)*
                }
            }

            /// The config that runs for `ctx` (`MethodSpec::resolve`).
            pub fn resolve(&self, ctx: &CallContext) -> Result<MethodConfig> {
                match *self {
                    $(MethodConfig::$variant(c) => c.resolve(ctx),)*
                }
            }

            /// The kernel of a config; resolve it first for the backend's defaults.
            pub fn kernel(&self) -> Method {
                match self {
                    $(MethodConfig::$variant(c) => c.kernel(),)*
                }
            }

            /// Occluder layers of a resolved config (0 for methods that read none).
            pub fn passes(&self) -> u32 {
                match self {
                    $(MethodConfig::$variant(c) => c.passes(),)*
                }
            }

            /// Occluder maps' (W, H) of a resolved config (None for methods
            /// that read no maps).
            pub fn occluder_resolution(&self) -> Option<(usize, usize)> {
                match self {
                    $(MethodConfig::$variant(c) => c.occluder_resolution(),)*
                }
            }

            /// Every method's row of `capabilities()`, in the registry's order.
            pub fn infos() -> Vec<MethodInfo> {
                vec![$(<$config as MethodSpec>::info()),*]
            }
        }
    };
}

method_configs! {
    Ssm(SsmConfig),
    Bitmask(BitmaskConfig),
    Exact(ExactConfig),
    /// Fernando 2005's percentage-closer soft shadows (`pcss.rs`).
    Pcss(PcssConfig),
    /// Chan & Durand 2003's smoothies (`smoothies/`).
    Smoothies(SmoothiesConfig),
    /// Scherzer 2005's practical shadow mapping (hard shadows from the
    /// light's centre or direction; `shadow_mapping/`).
    ShadowMapping(ShadowMappingConfig),
    Auto(AutoConfig),
}

impl MethodConfig {
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
}

/// The option `passes` of the occluder-map methods.
fn passes_option() -> OptionInfo {
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
fn occluder_resolution_option() -> OptionInfo {
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
fn hierarchy_option(default_on: bool) -> OptionInfo {
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
const PRECISION_SSM_ONLY: &str =
    "\"ssm\" (sums of occlusions); the other methods count samples exactly";
/// `samples` applies to the sampling methods only.
const SAMPLES_ONLY: &str = "the sampling methods (\"bitmask\", \"exact\")";

impl MethodSpec for SsmConfig {
    const NAME: &'static str = "ssm";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if o.samples.is_some() {
            return Err(refuse("samples", SAMPLES_ONLY));
        }
        SsmConfig::new(o.passes, o.occluder_resolution, o.hierarchy, o.precision)
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        let c = self;
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
        Ok(MethodConfig::Ssm(SsmConfig {
            passes: Some(passes),
            occluder_resolution: Some(occ),
            hierarchy: Some(hierarchy),
            precision: c.precision,
        }))
    }
    fn kernel(&self) -> Method {
        Method::Ssm {
            hierarchy: self.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
            precision: self.precision,
        }
    }
    fn passes(&self) -> u32 {
        self.passes.unwrap_or(DEFAULT_PASSES)
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "ssm",
            config: "Ssm",
            summary: "Soft shadow maps (Atty et al. 2005) as published: micro-patches of the \
                      occluder maps back-projected onto the light, their occlusions summed",
            reads: vec![Input::OccluderLayers],
            backends: Backend::built().to_vec(),
            options: vec![
                passes_option(),
                occluder_resolution_option(),
                hierarchy_option(HIERARCHY_DEFAULT_SSM),
                OptionInfo {
                    name: "precision",
                    kind: Kind::Choice(Precision::ALL.iter().map(|p| p.name()).collect()),
                    default: Value::Str(Precision::default().name()),
                    default_doc: "f32, each occluder row summed on its own",
                    doc: "how the occlusions are summed (paper Appendix A): f32 two-level, f64, \
                          emulated FP16 blending, or FP16 in batches of about sqrt(M)",
                    restricted_on: vec![(Backend::Gpu, vec![Value::Str(Precision::F32.name())])],
                },
            ],
        }
    }
}

impl MethodSpec for BitmaskConfig {
    const NAME: &'static str = "bitmask";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if o.precision.is_some() {
            return Err(refuse("precision", PRECISION_SSM_ONLY));
        }
        BitmaskConfig::new(
            o.samples,
            o.passes,
            o.occluder_resolution,
            o.hierarchy,
            None,
        )
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        let c = self;
        let (passes, occ, hierarchy) = resolve_maps(
            c.passes,
            c.occluder_resolution,
            c.hierarchy,
            HIERARCHY_DEFAULT_BITMASK,
            ctx,
        )?;
        Ok(MethodConfig::Bitmask(BitmaskConfig {
            samples: c.samples,
            gaps: c.gaps,
            passes: Some(passes),
            occluder_resolution: Some(occ),
            hierarchy: Some(hierarchy),
        }))
    }
    fn kernel(&self) -> Method {
        Method::Bitmask {
            samples: self.samples,
            hierarchy: self.hierarchy.unwrap_or(HIERARCHY_DEFAULT_BITMASK),
            gaps: self.gaps,
        }
    }
    fn passes(&self) -> u32 {
        self.passes.unwrap_or(DEFAULT_PASSES)
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "bitmask",
            config: "Bitmask",
            summary: "The same micro-patches marking the light samples they hide in a bit mask \
                      per receiver, merged by OR (Schwarz & Stamminger 2007)",
            reads: vec![Input::OccluderLayers],
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "samples",
                    kind: Kind::OneOf(bitmask::SAMPLE_COUNTS.iter().map(|&n| n as i64).collect()),
                    default: Value::Int(DEFAULT_SAMPLES as i64),
                    default_doc: "256",
                    doc: "light samples per receiver, a multi-jittered pattern shared by all \
                          receivers",
                    restricted_on: vec![],
                },
                passes_option(),
                occluder_resolution_option(),
                hierarchy_option(HIERARCHY_DEFAULT_BITMASK),
                OptionInfo {
                    name: "gaps",
                    kind: Kind::Choice(bitmask::Gaps::ALL.iter().map(|g| g.name()).collect()),
                    default: Value::Str(bitmask::Gaps::default().name()),
                    default_doc: "closed",
                    doc: "how neighbouring micro-patches meet: closed, connected micro-quads \
                          (no light between neighbours on one surface; a depth step steeper \
                          than 76° from the light's direction stays open); open, the flat \
                          per-texel micro-patches of the paper, whose gaps leak light (§4.1.2)",
                    restricted_on: vec![],
                },
            ],
        }
    }
}

impl MethodSpec for ExactConfig {
    const NAME: &'static str = "exact";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
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
                return Err(refuse(
                    opt,
                    "the occluder-map methods (\"ssm\", \"bitmask\"); \"exact\" traces the occluder triangles",
                ));
            }
        }
        if o.precision.is_some() {
            return Err(refuse("precision", PRECISION_SSM_ONLY));
        }
        ExactConfig::new(o.samples)
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        if ctx.depth_layers.is_some() {
            return Err(Error::invalid(
                "method",
                "\"exact\" traces the occluder triangles, which depth maps do not have; \
                 use soft_shadow_map with meshes",
            ));
        }
        Ok(MethodConfig::Exact(self))
    }
    fn kernel(&self) -> Method {
        Method::Exact {
            samples: self.samples,
        }
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "exact",
            config: "Exact",
            summary: "Ray casting against the occluder triangles (a BVH) with stratified light \
                      samples, jittered deterministically: converges to the true visibility",
            reads: vec![Input::OccluderTriangles],
            backends: Backend::built().to_vec(),
            options: vec![OptionInfo {
                name: "samples",
                kind: Kind::Int {
                    min: 1,
                    max: MAX_SAMPLES as i64,
                },
                default: Value::Int(DEFAULT_SAMPLES as i64),
                default_doc: "256 (a 16x16 stratification)",
                doc: "light samples per receiver",
                restricted_on: vec![],
            }],
        }
    }
}

impl MethodSpec for PcssConfig {
    const NAME: &'static str = "pcss";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if let Some(opt) = o.given().into_iter().find(|o| *o != "occluder_resolution") {
            return Err(refuse(opt, "other methods; give PCSS(...) its own options"));
        }
        PcssConfig::new(None, o.occluder_resolution)
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        // From depth maps: the front layer the user gave.
        let (_, occ, _) = resolve_maps(
            Some(1),
            self.occluder_resolution,
            Some(false),
            false,
            &CallContext {
                depth_layers: ctx.depth_layers.map(|(_, shape)| (1, shape)),
                ..*ctx
            },
        )?;
        Ok(MethodConfig::Pcss(PcssConfig {
            occluder_resolution: Some(occ),
            ..self
        }))
    }
    fn kernel(&self) -> Method {
        Method::Pcss {
            max_taps: self.max_taps,
        }
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
            name: "pcss",
            config: "PCSS",
            summary: "Percentage-closer soft shadows (Fernando 2005), what real-time engines \
                      ship: a blocker search on the shadow map, the penumbra estimated from the \
                      mean blocker depth, a box PCF of that width",
            reads: vec![Input::OccluderLayers],
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "max_taps",
                    kind: Kind::Int {
                        min: 1,
                        max: super::pcss::MAX_TAPS as i64,
                    },
                    default: Value::Int(super::pcss::DEFAULT_MAX_TAPS as i64),
                    default_doc: "16",
                    doc: "taps per axis of the blocker search and of the filter: a box spanning \
                          more texels is sampled by this many strata (bounded work per point)",
                    restricted_on: vec![],
                },
                occluder_resolution_option(),
            ],
        }
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
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        if ctx.depth_layers.is_some() {
            return Err(Error::invalid(
                "method",
                "Smoothies find the occluders' silhouette edges, which depth maps do not \
                 have; use soft_shadow_map with meshes",
            ));
        }
        Ok(MethodConfig::Smoothies(SmoothiesConfig {
            occluder_resolution: Some(self.occluder_resolution.unwrap_or(ctx.resolution)),
            ..self
        }))
    }
    fn kernel(&self) -> Method {
        Method::Smoothies {
            width: self.width,
            falloff: self.falloff,
        }
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
            reads: vec![Input::OccluderLayers, Input::OccluderTriangles],
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
                    kind: Kind::Choice(
                        super::smoothies::Falloff::ALL
                            .iter()
                            .map(|f| f.name())
                            .collect(),
                    ),
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

impl MethodSpec for ShadowMappingConfig {
    const NAME: &'static str = "shadow_mapping";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if let Some(opt) = o.given().first() {
            return Err(refuse(
                opt,
                "the soft shadow map methods; give ShadowMapping(...) its own options",
            ));
        }
        Ok(ShadowMappingConfig::default())
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
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
        Ok(MethodConfig::ShadowMapping(self))
    }
    fn kernel(&self) -> Method {
        Method::ShadowMapping(*self)
    }
    fn info() -> MethodInfo {
        use super::shadow_mapping::config::{DEFAULT_SM_RESOLUTION, MAX_SM_SIDE};
        let part = |name, classes: Vec<&'static str>, doc| OptionInfo {
            name,
            kind: Kind::Config(classes),
            default: Value::Resolved,
            default_doc: "None (off)",
            doc,
            restricted_on: vec![],
        };
        MethodInfo {
            name: "shadow_mapping",
            config: "ShadowMapping",
            summary: "The standard shadow map from the light's centre or direction with Scherzer \
                  2005's practical extensions: bias methods, PCF, focusing on the \
                  intersection body, LiSPSM (directional lights), the eye-space blur; hard \
                  shadows, the eye view only",
            reads: vec![Input::SceneTriangles, Input::Camera],
            backends: Backend::built().to_vec(),
            options: vec![
            OptionInfo {
                name: "resolution",
                kind: Kind::Resolution {
                    max_texels: (MAX_SM_SIDE * MAX_SM_SIDE) as i64,
                },
                default: Value::Int(DEFAULT_SM_RESOLUTION as i64),
                default_doc: "2048 x 2048 (Scherzer's)",
                doc: "the shadow map's (W, H), each side at most 16384",
                restricted_on: vec![],
            },
            OptionInfo {
                name: "bias",
                kind: Kind::Config(vec![
                    "ConstantBias",
                    "SlopeScaleBias",
                    "LinearDepthBias",
                    "BackFaces",
                    "MidpointBias",
                ]),
                default: Value::Str("SlopeScaleBias"),
                default_doc:
                    "SlopeScaleBias(constant=4, slope=2): glPolygonOffset(2, 4), Scherzer's",
                doc: "how the depth test keeps surfaces from shadowing themselves (Scherzer §4.2)",
                restricted_on: vec![],
            },
            part(
                "filter",
                vec!["PCF"],
                "percentage-closer filtering of the depth test",
            ),
            part(
                "warp",
                vec!["LiSPSM"],
                "LiSPSM (directional lights only): more texels near the camera",
            ),
            OptionInfo {
                name: "focus",
                kind: Kind::Bool,
                default: Value::Bool(true),
                default_doc: "True",
                doc: "fit the map to the intersection body B (view frustum and scene bounds, \
                      extended toward the light); False: to the whole scene",
                restricted_on: vec![],
            },
            part(
                "blur",
                vec!["EyeSpaceBlur"],
                "the depth-dependent eye-space blur of the shadow image (Scherzer §4.3)",
            ),
        ],
        }
    }
}

impl MethodSpec for AutoConfig {
    const NAME: &'static str = "auto";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        // The rule's choice is "ssm": its options given beside "auto"
        // replace the rule's.
        if o.samples.is_some() {
            return Err(refuse("samples", SAMPLES_ONLY));
        }
        Ok(AutoConfig {
            given: SsmConfig::new(o.passes, o.occluder_resolution, o.hierarchy, o.precision)?,
            target: Default::default(),
        })
    }
    fn resolve(self, ctx: &CallContext) -> Result<MethodConfig> {
        let given = self.given;
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
        ssm.resolve(ctx)
    }
    // What "auto" always resolves to.
    fn kernel(&self) -> Method {
        Method::Ssm {
            hierarchy: self.given.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
            precision: self.given.precision,
        }
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "auto",
            config: "Auto",
            summary: "A plan, not a method: without a target, \"ssm\" with two passes and \
                      occluder maps at a quarter of the output's resolution (at least 64, at \
                      most the output's), the point of the study's accuracy-time plane furthest \
                      ahead of ray tracing; with error= or time=, the setting planned from the \
                      scene (light-view maps from meshes; sm.plan says why)",
            reads: vec![Input::OccluderLayers],
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "error",
                    kind: Kind::Float,
                    default: Value::Resolved,
                    default_doc: "None (no target)",
                    doc: "the error to reach (the paper's §4.2.1 metric, mean |V - V_ref| over \
                          the shadow), in [1e-4, 1]: the cheapest setting measured within it",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "time",
                    kind: Kind::Float,
                    default: Value::Resolved,
                    default_doc: "None (no budget)",
                    doc: "a time budget in seconds, in [1e-6, 1e6]: a timed probe, then the most \
                          accurate setting predicted to fit; not with error",
                    restricted_on: vec![],
                },
            ],
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
        let r = MethodConfig::Auto(AutoConfig::default())
            .resolve(&cpu((512, 100)))
            .unwrap();
        assert_eq!(r.occluder_resolution(), Some((128, 64)));
        assert_eq!(r.passes(), 2);
        let r = MethodConfig::Auto(AutoConfig::default())
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
