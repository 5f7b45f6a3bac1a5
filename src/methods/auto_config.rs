//! `method="auto"` without a target: the rule (`auto_rule`), the config
//! `ss.Auto` holds (`AutoConfig`) and its `MethodSpec`, which resolves to
//! the `SsmConfig` the rule picks (with a target, the plan of `crate::auto`).

use super::config::{CallContext, LooseOptions, MethodSpec};
use super::config::{DEFAULT_PASSES, SAMPLES_ONLY};
use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::kernel::Kernel;
use super::ssm::{Precision, SsmConfig, SsmKernel};
use crate::backend::Backend;
use crate::error::{Error, Result};

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

/// What the eye view's default call (`ss.Auto()`, nothing given, no
/// target) runs on `backend`: `exact`'s 256 samples, on the CPU behind a
/// probe of 16 (`probe.rs`: only the pixels it is unsure of trace all 256).
///
/// Issue 28 measured the map rule (`auto_rule`) on scenes built as users
/// build them (closed boxes, real assets): 0.02-0.22 over the shadowed
/// pixels with acne and leaks, where `Exact(probe=16)` stays within 1e-4 of
/// `Exact()`'s error (0.0001-0.014) at 0.9-5.2x less time
/// (docs/benchmarks/scenes_320x240.md, scenes_640x480.md). The GPU traces every ray of every
/// pixel (it has no probe) and is fast enough to.
pub fn eye_default(backend: Backend) -> super::ExactConfig {
    super::ExactConfig {
        samples: super::config::DEFAULT_SAMPLES,
        probe: (backend == Backend::Cpu).then_some(EYE_PROBE),
        engine: None,
    }
}

/// The probe's light samples of the eye view's default call: a 4 x 4
/// stratification, a sliver of penumbra it misses is under a quarter of
/// the light's width (`probe.rs`).
pub const EYE_PROBE: u32 = 16;

/// What `ss.Auto` holds: the options given beside `method="auto"` (they
/// override the rule's: `ss.Auto()` holds none) and the target. Without a
/// target a rule that resolves to `Ssm`; with one (`ss.Auto(error=...)`) a
/// plan made from the scene (`crate::auto`), elsewhere the rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct AutoConfig {
    pub given: SsmConfig,
    pub target: super::target::Target,
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
    type Resolved = SsmConfig;
    /// What "auto" always resolves to.
    type Kernel = SsmKernel;
    fn kernel(&self) -> SsmKernel {
        self.given.kernel()
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
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

    fn info() -> MethodInfo {
        MethodInfo {
            name: "auto",
            config: "Auto",
            summary: "A plan, not a method: without a target, \"ssm\" with two passes and \
                      occluder maps at a quarter of the output's resolution (at least 64, at \
                      most the output's), the point of the study's accuracy-time plane furthest \
                      ahead of ray tracing; with error= or time=, the setting planned from the \
                      scene (light-view maps from meshes; sm.plan says why)",
            // The kernel's (`Kernel::READS`).
            reads: SsmKernel::READS.to_vec(),
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
