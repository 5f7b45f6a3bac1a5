//! `ss.Auto(error=..., time=...)`: the computation planned from the scene
//! and the target, each decision with the number that made it.
//!
//! The planner reads what the framed scene says cheaply (light-space depth
//! ranges of occluders and receivers, the light's size, the map's texel) and
//! takes, in order:
//!
//! 1. *Hard shadows*: where every penumbra is under half a texel of the
//!    output (the widest, L (w_near - w_far) with w = 1/depth, from the
//!    nearest occluder to the farthest receiver, §3.3 of Atty et al. 2005),
//!    the light is treated as a point: the hard shadow map.
//! 2. *Receivers out of reach*: the part of the map no occluder's penumbra
//!    can reach is lit without shading (the gather skips it); the plan says
//!    how much.
//! 3. *Sum or union*: where the occluders are one plane parallel to the
//!    light, no two back-projections overlap and the SSM's sum is exact
//!    (§3.4); elsewhere they overlap and the sum counts light twice, so the
//!    bitmask's union runs unless the target allows the sum's error.
//! 4. *Samples, hierarchy and occluder resolution from the target*: the
//!    cheapest setting whose error, measured on the study's scenes and the
//!    hard surfaces at 256² against Mitsuba (`benchmarks/bench_gaps.py`,
//!    docs/benchmarks/gaps.md), is within the target; for a loose target
//!    the occluder maps are coarsened while the narrowest penumbra still
//!    spans `COARSE_TEXELS` occluder texels.
//!
//! `time=` plans by a probe: the cheapest soft setting runs first (its result
//! is kept when nothing better fits), and each more accurate setting's time
//! is predicted from it by the largest ratio measured on the study's scenes.

use crate::geom::light_shape::LightShape;
use crate::methods::shadow_mapping::config::Real;
use crate::methods::target::Target;
use crate::methods::{BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};

/// What the planner reads of a framed scene (kernel units).
#[derive(Debug, Clone, Copy)]
pub struct SceneStats {
    /// Output (W, H) and tangent half-extents.
    pub resolution: (usize, usize),
    pub extent: [f64; 2],
    pub light_shape: LightShape,
    /// 1/depth of the nearest and farthest occluder vertex.
    pub occ_w_near: f64,
    pub occ_w_far: f64,
    /// 1/depth of the nearest and farthest receiver vertex.
    pub rec_w_near: f64,
    pub rec_w_far: f64,
    /// Tangent bounds of the occluders [x_lo, x_hi, y_lo, y_hi].
    pub occ_bounds: [f64; 4],
    /// Whether every occluder vertex shares one depth (a plane parallel to
    /// the light, or several at one depth).
    pub occ_flat: bool,
    /// Whether every occluder vertex lies on one plane (any orientation).
    pub occ_planar: bool,
}

impl SceneStats {
    /// The output's texel (the larger side), tangent units.
    fn texel(&self) -> f64 {
        (2.0 * self.extent[0] / self.resolution.0 as f64)
            .max(2.0 * self.extent[1] / self.resolution.1 as f64)
    }

    fn light(&self) -> f64 {
        self.light_shape.largest_width()
    }

    /// The widest penumbra, in output texels.
    pub fn widest_penumbra(&self) -> f64 {
        self.light() * (self.occ_w_near - self.rec_w_far).max(0.0) / self.texel()
    }

    /// The narrowest penumbra, in output texels: 0 where occluders and
    /// receivers share depths (contact).
    pub fn narrowest_penumbra(&self) -> f64 {
        self.light() * (self.occ_w_far - self.rec_w_near).max(0.0) / self.texel()
    }

    /// The fraction of the map no occluder's penumbra reaches.
    pub fn out_of_reach(&self) -> f64 {
        let reach = 0.5 * self.light() * (self.occ_w_near - self.rec_w_far).max(0.0);
        let [x0, x1, y0, y1] = self.occ_bounds;
        let [tx, ty] = self.extent;
        let w = ((x1 + reach).min(tx) - (x0 - reach).max(-tx)).max(0.0);
        let h = ((y1 + reach).min(ty) - (y0 - reach).max(-ty)).max(0.0);
        (1.0 - w * h / (4.0 * tx * ty)).clamp(0.0, 1.0)
    }
}

/// One decision of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// A short name: "hard", "out_of_reach", "union", "setting".
    pub name: &'static str,
    pub taken: bool,
    /// Why, with the number that decided.
    pub why: String,
}

/// What the planner decided, and the config it chose.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub decisions: Vec<Decision>,
    /// Run the hard shadow map (the light as a point).
    pub hard: bool,
    pub config: MethodConfig,
    /// The setting planned, where runs checked against the estimate
    /// replaced it (`refine.rs`: `config` is then the last run's); None
    /// where the planned run was kept.
    pub planned: Option<MethodConfig>,
    /// For a map setting chosen for an error target under COARSE_TARGET:
    /// the target less the setting's measured worst error, what `set_gaps`
    /// may spend (None: nothing to spend).
    pub slack: Option<f64>,
}

/// A setting the planner can choose, with its measured worst error and
/// the largest time ratio to the probe (`PROBE`) measured on the study's
/// scenes at 256² (docs/benchmarks/gaps.md, docs/methods/auto.md).
struct Candidate {
    label: &'static str,
    worst_error: f64,
    time_ratio: f64,
    config: fn((usize, usize)) -> MethodConfig,
}

/// The widest penumbra (output texels) from which the hierarchy pays:
/// measured at 256² (docs/benchmarks/gaps.md), bitmask 256 with the
/// hierarchy took 0.14-0.61x the time without it where penumbrae span 97-334
/// texels (near_light, slanted_receiver, two_spheres), 0.94-1.32x where they
/// span 51-102 (the bunnies, torus, tilted_plate, fence, contact_box).
pub const HIERARCHY_TEXELS: f64 = 80.0;
/// Occluder texels the narrowest penumbra must span before the occluder
/// maps are coarsened for a loose target.
pub const COARSE_TEXELS: f64 = 16.0;
/// The tightest target for which occluder maps are coarsened.
pub const COARSE_TARGET: f64 = 0.02;

fn bitmask(samples: u32, hierarchy: bool) -> MethodConfig {
    MethodConfig::Bitmask(BitmaskConfig {
        samples,
        hierarchy: Some(hierarchy),
        ..BitmaskConfig::default()
    })
}

/// The settings in order of cost, the cheapest (the probe) first.
const CANDIDATES: [Candidate; 4] = [
    Candidate {
        label: "ssm, 2 passes, quarter-resolution occluder maps (the sum)",
        worst_error: 0.046,
        time_ratio: 1.0,
        config: |r| MethodConfig::Ssm(crate::methods::auto_rule(r)),
    },
    Candidate {
        label: "bitmask, 256 samples, gaps closed, hierarchy",
        worst_error: 0.0077,
        time_ratio: 33.0,
        config: |_| bitmask(256, true),
    },
    Candidate {
        label: "bitmask, 256 samples, gaps closed, no hierarchy",
        worst_error: 0.0061,
        time_ratio: 33.0,
        config: |_| bitmask(256, false),
    },
    Candidate {
        label: "bitmask, 1024 samples, gaps closed, no hierarchy",
        // Worst: bunny_on_floor's 0.0048. The fence's thin bars give 0.0051
        // at the output's resolution (Mitsuba's own noise there: 0.0041),
        // 0.0039 with the maps doubled, which any target under THIN_TARGET
        // takes (`Plan::refine_thin`).
        worst_error: 0.005,
        time_ratio: 76.0,
        config: |_| bitmask(1024, false),
    },
];

/// The light view's `exact` law, error about LIGHT_EXACT / sqrt(samples):
/// measured against 4096 samples on the test scenes (1024 samples:
/// 0.0012-0.0019, under 0.05 / 32). The plan's exact samples and a
/// refinement from a map setting (`refine.rs`) both read it; not refitted
/// on the fence.
pub const LIGHT_EXACT: f64 = 0.05;

/// exact's samples per receiver for `error` by `LIGHT_EXACT`'s law.
fn exact_samples_for(error: f64) -> u32 {
    let max = crate::methods::config::MAX_SAMPLES;
    let n = (LIGHT_EXACT / error).powi(2).ceil();
    square_samples(n.clamp(16.0, max as f64) as u32, max)
}

/// The plan for `stats` and `target`; `probe_seconds` is the probe's time
/// when planning for a budget (None: not run yet, the caller runs the probe
/// config and asks again).
pub fn plan(stats: &SceneStats, target: &Target, probe_seconds: Option<f64>) -> Plan {
    let res = stats.resolution;
    let mut d = vec![];
    let widest = stats.widest_penumbra();
    let hard = widest < 0.5;
    d.push(Decision {
        name: "hard",
        taken: hard,
        why: format!(
            "the widest penumbra spans {widest:.2} texels of the output ({}half a texel)",
            if hard { "under " } else { "at least " }
        ),
    });
    let out = stats.out_of_reach();
    d.push(Decision {
        name: "out_of_reach",
        taken: out > 0.0,
        why: format!(
            "{:.0}% of the map lies beyond every occluder's penumbra and is lit without shading",
            100.0 * out
        ),
    });
    if hard {
        return Plan {
            planned: None,
            decisions: d,
            hard: true,
            config: (CANDIDATES[0].config)(res),
            slack: None,
        };
    }
    // A plane seen from any point of the light covers each direction once:
    // the back-projections of its micro-patches do not overlap (§3.4).
    let flat = stats.occ_flat || stats.occ_planar;
    let mut slack = None;
    d.push(Decision {
        name: "union",
        taken: !flat,
        why: if stats.occ_flat {
            "the occluders are one plane parallel to the light: no back-projections overlap, \
             the sum is exact"
                .into()
        } else if flat {
            "the occluders are one plane (tilted against the light): no back-projections \
             overlap, the sum is exact up to its texels"
                .into()
        } else {
            "the occluders span depths off one plane: back-projections overlap, the sum \
             counts them twice"
                .into()
        },
    });
    let config = if flat {
        // The sum at the output's resolution: what remains is the texels'
        // discretization, whatever the target.
        MethodConfig::Ssm(SsmConfig {
            passes: Some(1),
            ..SsmConfig::default()
        })
    } else if let Some(Real(e)) = target.error {
        match CANDIDATES.iter().position(|c| c.worst_error <= e) {
            Some(mut k) => {
                // The hierarchy pays where penumbrae are wide (it skips
                // occluder blocks a receiver's window would scan); the
                // setting without it is as accurate or more.
                let narrow = k == 1 && widest < HIERARCHY_TEXELS;
                if narrow {
                    k = 2;
                }
                let c = &CANDIDATES[k];
                // Coarser maps spend the slack of targets from COARSE_TARGET.
                slack = (e < COARSE_TARGET).then_some(e - c.worst_error);
                d.push(Decision {
                    name: "setting",
                    taken: true,
                    why: format!(
                        "{}: measured error at most {} on the study's scenes and the hard \
                         surfaces, within the target {e}{}",
                        c.label,
                        c.worst_error,
                        if narrow {
                            format!(
                                "; no hierarchy: the widest penumbra spans {widest:.0} texels, \
                                 under {HIERARCHY_TEXELS}"
                            )
                        } else {
                            String::new()
                        }
                    ),
                });
                coarsen((c.config)(res), stats, e, &mut d)
            }
            None => {
                let samples = exact_samples_for(e);
                d.push(Decision {
                    name: "setting",
                    taken: true,
                    why: format!(
                        "no map setting measured within {e} (the best: {}); exact with {samples} \
                         samples (error about 0.05/sqrt(samples))",
                        CANDIDATES[CANDIDATES.len() - 1].worst_error
                    ),
                });
                MethodConfig::Exact(ExactConfig::of(samples))
            }
        }
    } else if let Some(Real(t)) = target.time {
        match probe_seconds {
            None => (CANDIDATES[0].config)(res),
            Some(p) => {
                let left = t - p;
                let best = CANDIDATES
                    .iter()
                    .rev()
                    .find(|c| c.time_ratio == 1.0 || c.time_ratio * p <= left)
                    .unwrap_or(&CANDIDATES[0]);
                d.push(Decision {
                    name: "setting",
                    taken: true,
                    why: format!(
                        "{}: the probe took {:.4} s, predicted {:.4} s (x{} measured at most) \
                         within the {:.4} s left of {t} s",
                        best.label,
                        p,
                        best.time_ratio * p,
                        best.time_ratio,
                        left.max(0.0)
                    ),
                });
                (best.config)(res)
            }
        }
    } else {
        d.push(Decision {
            name: "setting",
            taken: true,
            why: format!(
                "no target: {} (the study's point furthest ahead of ray tracing)",
                CANDIDATES[0].label
            ),
        });
        (CANDIDATES[0].config)(res)
    };
    Plan {
        planned: None,
        decisions: d,
        hard: false,
        config,
        slack,
    }
}

/// Occluder features this narrow (texels) lose a large share of their
/// width to the texel grid: a connected micro-quad's edge sits up to half
/// a texel off the true silhouette on each side, an eighth of such a bar.
pub const THIN_TEXELS: usize = 8;
/// The share of thin front texels above which a tight target doubles the
/// occluder maps' resolution. Measured at 256²: all of the fence's texels
/// (bars 5-8 texels wide), at most 0.3% on the study's scenes and the other
/// hard surfaces.
pub const THIN_SHARE: f64 = 0.25;
/// Targets under this (the fence's measured 0.0051 with thin bars at the
/// output's resolution; 0.0039 at twice it) refine thin occluders.
pub const THIN_TARGET: f64 = 0.0051;
/// A peeled layer "changes nothing" when the shadow it adds moves the
/// error metric by less than this: under the noise of a 1024-sample
/// reference (0.0013-0.0041, docs/benchmarks/gaps.md).
pub const LAYER_CHANGE: f64 = 0.001;

/// What closing the gaps changes in the planned maps' shadow, per unit of
/// what it changes in the coarse layer tries' shadow (`Plan::set_gaps`).
/// Measured at 0.01 on the study's scenes and the hard surfaces at 256² and
/// 512² (docs/methods/auto.md): 0.47-1.02 where the change is 0.002-0.019,
/// 2.76 on the fence at 512² (0.0007 coarse, 0.0019 full); rounded up.
pub const GAP_SCALE: f64 = 3.0;

/// The change one more occluder layer makes to a visibility map: the
/// error metric's form (mean |a - b| over texels shadowed in either).
pub fn layer_change(a: &[f32], b: &[f32]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        if x < 1.0 || y < 1.0 {
            sum += (x - y).abs() as f64;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

impl Plan {
    /// The union setting, if that is what the plan runs (its layers and
    /// thin occluders are then measured: `set_layers`, `refine_thin`).
    pub fn bitmask(&self) -> Option<BitmaskConfig> {
        match self.config {
            MethodConfig::Bitmask(c) if !self.hard => Some(c),
            _ => None,
        }
    }

    /// Whether the thin-feature measure can change this plan: a union
    /// setting under a target tighter than THIN_TARGET.
    pub fn thin_matters(&self, target: &Target) -> bool {
        self.bitmask().is_some() && target.error.is_some_and(|Real(e)| e < THIN_TARGET)
    }

    /// Doubles a union plan's occluder maps (`resolution`: their (W, H))
    /// where thin features make up more than THIN_SHARE of their front
    /// layer: `front` holds its (covered, thin) texels, measured where
    /// `thin_matters` (None: not measured).
    pub fn refine_thin(&mut self, front: Option<(usize, usize)>, resolution: (usize, usize)) {
        let Some(mut c) = self.bitmask() else {
            return;
        };
        let Some((covered, thin)) = front else {
            self.decisions.push(Decision {
                name: "thin_occluders",
                taken: false,
                why: format!("targets from {THIN_TARGET} keep the occluder maps' resolution"),
            });
            return;
        };
        let share = if covered == 0 {
            0.0
        } else {
            thin as f64 / covered as f64
        };
        let refine = share > THIN_SHARE;
        self.decisions.push(Decision {
            name: "thin_occluders",
            taken: refine,
            why: format!(
                "{:.0}% of the {covered} covered occluder texels lie in features at most \
                 {THIN_TEXELS} texels wide ({} {:.0}%){}",
                100.0 * share,
                if refine { "over" } else { "at most" },
                100.0 * THIN_SHARE,
                if refine {
                    format!(
                        ": occluder maps at twice the resolution, {}x{}",
                        2 * resolution.0,
                        2 * resolution.1
                    )
                } else {
                    String::new()
                }
            ),
        });
        if refine {
            c.occluder_resolution = Some((2 * resolution.0, 2 * resolution.1));
            self.config = MethodConfig::Bitmask(c);
        }
    }

    /// Opens a union plan's gaps (flat per-texel micro-patches, cheaper
    /// than connected quads) where closing them changes the shadow by less
    /// than the plan's slack: `change` is what closing them changed in the
    /// coarse shadow of the layer tries (`auto/measure.rs`, None: not
    /// measured). The metric is a mean of |differences| over one set of
    /// texels, so error(open) <= error(closed) + |open - closed|: with the
    /// coarse change scaled to the full maps' (GAP_SCALE, measured), the
    /// open setting stays within the target.
    pub fn set_gaps(&mut self, change: Option<f64>) {
        let MethodConfig::Bitmask(mut c) = self.config else {
            return;
        };
        let (Some(change), Some(slack)) = (change, self.slack) else {
            self.decisions.push(Decision {
                name: "gaps",
                taken: false,
                why: format!(
                    "closed: the gaps are opened only under targets under {COARSE_TARGET} \
                     (looser ones spend their slack on coarser maps)"
                ),
            });
            return;
        };
        let full = GAP_SCALE * change;
        let open = full <= slack;
        self.decisions.push(Decision {
            name: "gaps",
            taken: open,
            why: format!(
                "closing the gaps between micro-patches changed the coarse shadow by \
                 {change:.4} (about {full:.4} on the planned maps, x{GAP_SCALE} measured); \
                 the target leaves {slack:.4} over the setting's worst error: gaps {}",
                if open {
                    "open (flat micro-patches, cheaper)"
                } else {
                    "closed"
                }
            ),
        });
        if open {
            c.gaps = crate::methods::bitmask::Gaps::Open;
            self.config = MethodConfig::Bitmask(c);
        }
    }

    /// The occluder layers of a union plan, as the caller measured them
    /// on coarse maps (`auto/measure.rs`): `passes` taken (1: no texel
    /// sees a back surface); `surfaces` the texels that see a surface and a
    /// back behind it; `peeled[k]` the texels where the (k+3)-th layer holds
    /// a surface before the back, `changes[k]` what adding it changed.
    pub fn set_layers(
        &mut self,
        passes: u32,
        surfaces: [usize; 2],
        peeled: &[usize],
        changes: &[f64],
    ) {
        if let MethodConfig::Bitmask(mut c) = self.config {
            c.passes = Some(passes);
            self.config = MethodConfig::Bitmask(c);
        }
        let list = |v: Vec<String>| v.join(", ");
        let [covered, back] = surfaces;
        self.decisions.push(Decision {
            name: "layers",
            taken: passes != crate::methods::config::DEFAULT_PASSES,
            why: if passes == 1 {
                format!(
                    "none of the {covered} texels of the coarse occluder map sees a second \
                     surface: one layer (a back layer would repeat the front)"
                )
            } else if peeled.first().is_none_or(|&n| n == 0) {
                format!(
                    "{back} of the {covered} texels of the coarse occluder map see a back \
                     surface, none a third: front and back"
                )
            } else {
                format!(
                    "{back} of the {covered} texels of the coarse occluder map see a back \
                     surface; texels with a surface between front and back, per peeled layer: \
                     [{}]; what each changed in the coarse shadow: [{}] (under {LAYER_CHANGE} \
                     changes nothing): {passes} layers",
                    list(peeled.iter().map(|n| n.to_string()).collect()),
                    list(changes.iter().map(|c| format!("{c:.4}")).collect()),
                )
            },
        });
    }
}

/// The upper end of the 95% interval of the rule maps' error estimate in
/// the eye view (the mean |V - V_ref| over the pixels the reference
/// shadows, docs/accuracy.md; drawn as the plan draws it, 1024 pixels),
/// worst on the calibration scenes of `softshadow.scenes.as_built` at
/// 320x240: 0.330 (spheres_sun_high, true error 0.166; shelf_with_objects
/// 0.307, true 0.070). The plan is checked against the estimate after the
/// run (`refine.rs`), so the constant is what the estimate must show, not
/// the true error. Measured by `python benchmarks/fit_eye_plan.py`.
pub const EYE_RULE_ERROR: f64 = 0.33;
/// `exact`'s eye-view error estimate's upper end at n samples a pixel is
/// about EYE_EXACT / sqrt(n): the worst on the calibration scenes at 64
/// samples, blocks_on_table's 0.0136 (true error 0.0113), gives 0.109;
/// 0.12 leaves a tenth for scenes unlike them (fewer refinements).
pub const EYE_EXACT: f64 = 0.12;

/// The eye view's first `exact` run where `EYE_EXACT`'s law asks for more
/// samples: a pilot of 4 x 4. Its estimate settles the scenes whose
/// penumbrae are narrow (the sun, small lights) at a fraction of the law's
/// count, which is fitted to the widest; the others run the law's count
/// after it (`refine.rs` grows an `exact` run below the law's count to at
/// most that count); the runs share their first hits, framing and BVH
/// (`pipeline::eye_view::Traced`). Measured on the calibration scenes at
/// 320x240: spheres_sun_high and stairs_low_sun met 0.005 at 16 samples
/// (the estimate's upper end 0.0017) where the law runs 576, 3-25x less
/// time; the six area-light scenes missed (0.024-0.035) and then ran the
/// law's count, the pilot adding up to 21% to their time (docs/methods/auto.md).
pub const EYE_PILOT: u32 = 16;

/// The most samples a refinement gives `exact` (its estimate traces four
/// times as many, within `MAX_SAMPLES`).
pub const MAX_REFINED_SAMPLES: u32 = crate::methods::config::MAX_SAMPLES / 4;

/// The light view's refinement from a map setting (`refine.rs`): `exact`
/// with (LIGHT_REFINE / e)² samples. Measured against `exact` at 1024
/// samples on the fence at 256²: 100 samples erred 0.0164 (0.164·/√n),
/// against the 0.0050 `LIGHT_EXACT`'s law promised; the square plate at
/// 64², 64 samples against 256: 0.0131 (0.105/√n). A stratified sample's
/// error falls faster than 1/√n, so the law fitted at 1024 samples
/// promises too much at a hundred; 0.17 covers both (not fitted on the
/// calibration scenes).
pub const LIGHT_REFINE: f64 = 0.17;

/// `exact`'s samples for `target` by the law `error = c / sqrt(samples)`,
/// rounded up to a near-square stratification (`LightShape::square_count`).
pub fn exact_samples(c: f64, target: f64) -> u32 {
    let n = (c / target).powi(2).ceil();
    if n.is_finite() {
        square_samples((n as u32).max(1), MAX_REFINED_SAMPLES)
    } else {
        MAX_REFINED_SAMPLES
    }
}

/// `n` samples rounded up to a near-square stratification, at most `max`
/// (a square: 128² or 256²).
pub fn square_samples(n: u32, max: u32) -> u32 {
    LightShape::square_count(n.min(max)).min(max)
}

/// The plan of an eye view (`ss.render`) for `target`: the rule's maps
/// where their measured error is within it, else `exact` with the samples
/// its measured error law asks for. A time budget runs the rule (budgets
/// are planned for light-view maps only). `rule`: the call's `Auto`
/// without its target (the eye view sizes the rule's maps itself);
/// `maps_ok` false where the rule's maps were not measured (any light but
/// a rectangle or the sun): `exact` by its law at every target.
pub fn plan_eye(target: &Target, rule: MethodConfig, light: &str, maps_ok: bool) -> Plan {
    let (config, why) = match target.error {
        Some(Real(e)) if e >= EYE_RULE_ERROR && maps_ok => (
            rule,
            format!(
                "the rule's maps: their error estimate within {EYE_RULE_ERROR} on every \
                 calibration scene, within the target {e}"
            ),
        ),
        Some(Real(e)) => {
            let n = exact_samples(EYE_EXACT, e);
            let first = n.min(EYE_PILOT);
            let then = if first < n {
                format!(
                    ", first with {first} (a pilot: where its estimate meets the target it \
                     stands)"
                )
            } else {
                String::new()
            };
            let no_maps = if maps_ok {
                format!(
                    "no map setting measured within {e} in the eye view (the rule's maps: \
                     {EYE_RULE_ERROR})"
                )
            } else {
                format!(
                    "the rule's maps are planned under rectangles and the sun only (their error \
                     was measured there), not under a {light}"
                )
            };
            (
                MethodConfig::Exact(ExactConfig::of(first)),
                format!(
                    "{no_maps}; exact with {n} samples a pixel (its error estimate within \
                     {EYE_EXACT}/sqrt(samples) on every calibration scene){then}"
                ),
            )
        }
        None if !maps_ok => (
            MethodConfig::Exact(ExactConfig::of(crate::methods::config::DEFAULT_SAMPLES)),
            format!(
                "time budgets are planned for light-view maps under rectangles and the sun \
                 only, not under a {light}: exact with its default samples"
            ),
        ),
        None => (
            rule,
            "time budgets are planned for light-view maps only: the rule's maps (the eye \
             view's fastest setting)"
                .to_string(),
        ),
    };
    Plan {
        planned: None,
        decisions: vec![Decision {
            name: "setting",
            taken: true,
            why,
        }],
        hard: false,
        config,
        slack: None,
    }
}

/// Coarser occluder maps for a bitmask setting under a loose target (at
/// least COARSE_TARGET): halved while the narrowest penumbra spans
/// COARSE_TEXELS occluder texels, never below 64.
///
/// The penumbrae say nothing of thin occluders: at 0.01 the fence's bars
/// (2 texels of a 128² map) came out at 0.0161 (docs/benchmarks/gaps.md),
/// hence the looser bound.
fn coarsen(
    config: MethodConfig,
    stats: &SceneStats,
    error: f64,
    d: &mut Vec<Decision>,
) -> MethodConfig {
    let MethodConfig::Bitmask(mut c) = config else {
        return config;
    };
    let narrow = stats.narrowest_penumbra();
    let (w, h) = stats.resolution;
    let mut f = 1usize;
    while error >= COARSE_TARGET
        && narrow / (2 * f) as f64 >= COARSE_TEXELS
        && w / (2 * f) >= 64
        && h / (2 * f) >= 64
    {
        f *= 2;
    }
    d.push(Decision {
        name: "occluder_resolution",
        taken: f > 1,
        why: format!(
            "the narrowest penumbra spans {narrow:.1} output texels; occluder maps at 1/{f} of \
             the output's resolution keep at least {COARSE_TEXELS} of their texels across it{}",
            if error < COARSE_TARGET {
                " (targets under 0.02 keep the full resolution)"
            } else {
                ""
            }
        ),
    });
    if f > 1 {
        c.occluder_resolution = Some((w / f, h / f));
    }
    MethodConfig::Bitmask(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::bitmask::Gaps;

    fn stats() -> SceneStats {
        SceneStats {
            resolution: (256, 256),
            extent: [0.35, 0.35],
            light_shape: LightShape::rect([1.0, 1.0]),
            occ_w_near: 1.0 / 2.0,
            occ_w_far: 1.0 / 2.9,
            rec_w_near: 0.25,
            rec_w_far: 0.25,
            occ_bounds: [-0.1, 0.1, -0.1, 0.1],
            occ_flat: false,
            occ_planar: false,
        }
    }

    #[test]
    fn a_tiny_light_is_a_point_and_a_big_one_is_not() {
        let mut s = stats();
        assert!(!plan(&s, &Target::default(), None).hard);
        s.light_shape = LightShape::rect([1e-4, 1e-4]);
        assert!(plan(&s, &Target::default(), None).hard);
    }

    #[test]
    fn tighter_targets_pick_costlier_settings() {
        let s = stats();
        let pick = |e: f64| plan(&s, &Target::new(Some(e), None).unwrap(), None).config;
        assert!(matches!(pick(0.05), MethodConfig::Ssm(_)));
        assert!(matches!(pick(0.01), MethodConfig::Bitmask(c) if c.samples == 256));
        assert!(matches!(pick(0.005), MethodConfig::Bitmask(c) if c.samples == 1024));
        assert!(matches!(pick(0.001), MethodConfig::Exact(c) if c.samples == 2500));
    }

    #[test]
    fn the_hierarchy_runs_where_penumbrae_are_wide_only() {
        let t = Target::new(Some(0.01), None).unwrap();
        let hierarchy = |s: &SceneStats| match plan(s, &t, None).config {
            MethodConfig::Bitmask(c) => c.hierarchy,
            other => panic!("{other:?}"),
        };
        let mut s = stats();
        // (1/2 - 1/4) / (0.7 / 256) = 91 texels.
        assert_eq!(hierarchy(&s), Some(true));
        s.light_shape = LightShape::rect([0.5, 0.5]);
        assert_eq!(hierarchy(&s), Some(false));
    }

    #[test]
    fn wide_penumbrae_coarsen_the_occluder_maps_for_loose_targets_only() {
        let s = stats();
        // Narrowest: (1/2.9 - 1/4) / (0.7 / 256) = 34.7 texels: one halving
        // (17.3 >= COARSE_TEXELS at 1/2, 8.7 at 1/4).
        let c = plan(&s, &Target::new(Some(0.02), None).unwrap(), None).config;
        assert!(matches!(c, MethodConfig::Bitmask(b) if b.occluder_resolution == Some((128, 128))));
        let c = plan(&s, &Target::new(Some(0.01), None).unwrap(), None).config;
        assert!(matches!(c, MethodConfig::Bitmask(b) if b.occluder_resolution.is_none()));
        let mut contact = s;
        contact.occ_w_far = 0.25;
        let c = plan(&contact, &Target::new(Some(0.02), None).unwrap(), None).config;
        assert!(matches!(c, MethodConfig::Bitmask(b) if b.occluder_resolution.is_none()));
    }

    #[test]
    fn a_flat_occluder_takes_the_sum_whatever_the_target() {
        let mut s = stats();
        s.occ_flat = true;
        let p = plan(&s, &Target::new(Some(0.002), None).unwrap(), None);
        assert!(matches!(p.config, MethodConfig::Ssm(_)));
        assert!(p.decisions.iter().any(|d| d.name == "union" && !d.taken));
    }

    #[test]
    fn a_budget_picks_what_the_probe_predicts_fits() {
        let s = stats();
        let t = Target::new(None, Some(1.0)).unwrap();
        assert!(matches!(plan(&s, &t, None).config, MethodConfig::Ssm(_)));
        // Probe 1 ms: 1024 samples predicted 0.076 s, fits.
        assert!(
            matches!(plan(&s, &t, Some(1e-3)).config, MethodConfig::Bitmask(c) if c.samples == 1024)
        );
        // Probe 0.1 s: nothing else fits.
        assert!(matches!(
            plan(&s, &t, Some(0.1)).config,
            MethodConfig::Ssm(_)
        ));
    }

    fn union_plan(target: &Target) -> Plan {
        let p = plan(&stats(), target, None);
        assert!(p.bitmask().is_some());
        p
    }

    #[test]
    fn gaps_open_only_where_closing_them_fits_in_the_slack() {
        let t = Target::new(Some(0.01), None).unwrap();
        let gaps = |p: &Plan| match p.config {
            MethodConfig::Bitmask(c) => c.gaps,
            _ => unreachable!("a union plan"),
        };
        let slack = union_plan(&t).slack.expect("a tight target leaves slack");
        assert!(slack > 0.0 && slack < 0.01);
        let mut nothing = union_plan(&t);
        nothing.set_gaps(Some(0.0));
        assert_eq!(gaps(&nothing), Gaps::Open);
        let mut small = union_plan(&t);
        small.set_gaps(Some(0.99 * slack / GAP_SCALE));
        assert_eq!(gaps(&small), Gaps::Open);
        let mut large = union_plan(&t);
        large.set_gaps(Some(1.01 * slack / GAP_SCALE));
        assert_eq!(gaps(&large), Gaps::Closed);
        let mut unmeasured = union_plan(&t);
        unmeasured.set_gaps(None);
        assert_eq!(gaps(&unmeasured), Gaps::Closed);
        // Loose targets spend their slack on coarser maps.
        let mut loose = union_plan(&Target::new(Some(0.03), None).unwrap());
        assert_eq!(loose.slack, None);
        loose.set_gaps(Some(0.0));
        assert_eq!(gaps(&loose), Gaps::Closed);
        for p in [&nothing, &large, &loose] {
            assert!(p.decisions.iter().any(|d| d.name == "gaps"));
        }
    }

    #[test]
    fn layers_are_what_the_caller_measured() {
        let t = Target::new(Some(0.01), None).unwrap();
        let mut single = union_plan(&t);
        single.set_layers(1, [100, 0], &[], &[]);
        assert_eq!(single.config.passes(), 1);
        assert!(single
            .decisions
            .iter()
            .any(|d| d.name == "layers" && d.taken));
        let mut closed = union_plan(&t);
        closed.set_layers(3, [100, 90], &[40, 0], &[0.004]);
        assert_eq!(closed.config.passes(), 3);
        let d = closed
            .decisions
            .iter()
            .find(|d| d.name == "layers")
            .unwrap();
        assert!(d.taken && d.why.contains("[40, 0]") && d.why.contains("0.0040"));
        let mut two = union_plan(&t);
        two.set_layers(2, [100, 90], &[0], &[]);
        assert!(two.decisions.iter().any(|d| d.name == "layers" && !d.taken));
    }

    #[test]
    fn thin_occluders_double_the_maps_under_the_thin_target_only() {
        let tight = Target::new(Some(0.005), None).unwrap();
        let mut p = union_plan(&tight);
        assert!(p.thin_matters(&tight));
        p.refine_thin(Some((1000, 600)), (256, 256));
        assert_eq!(p.config.occluder_resolution(), Some((512, 512)));
        let mut few = union_plan(&tight);
        few.refine_thin(Some((1000, 100)), (256, 256));
        assert_eq!(few.config.occluder_resolution(), None);
        let loose = Target::new(Some(0.01), None).unwrap();
        assert!(!union_plan(&loose).thin_matters(&loose));
    }

    #[test]
    fn a_layer_change_is_the_mean_difference_over_shadowed_texels() {
        assert_eq!(layer_change(&[1.0, 1.0], &[1.0, 1.0]), 0.0);
        // Texel 0 shadowed in one map only, texel 1 lit in both.
        assert!((layer_change(&[0.5, 1.0, 0.2], &[1.0, 1.0, 0.3]) - 0.3).abs() < 1e-6);
    }

    #[test]
    fn the_eye_view_takes_the_rule_for_loose_targets_and_exact_below() {
        let rule = MethodConfig::Auto(crate::methods::AutoConfig::default());
        let pick = |e: f64| {
            plan_eye(
                &Target::new(Some(e), None).unwrap(),
                rule,
                "RectLight",
                true,
            )
            .config
        };
        assert_eq!(pick(EYE_RULE_ERROR), rule);
        assert!(matches!(pick(0.05), MethodConfig::Exact(c) if c.samples == 6));
        // Below 1/9 of the rule's error the law asks more than the pilot:
        // the pilot runs first, and the decision names the law's count.
        for (e, n) in [(0.01, 144), (0.005, 576)] {
            let p = plan_eye(
                &Target::new(Some(e), None).unwrap(),
                rule,
                "RectLight",
                true,
            );
            assert!(matches!(p.config, MethodConfig::Exact(c) if c.samples == EYE_PILOT));
            assert!(p.decisions[0]
                .why
                .contains(&format!("exact with {n} samples")));
        }
        let budget = plan_eye(
            &Target::new(None, Some(1.0)).unwrap(),
            rule,
            "RectLight",
            true,
        );
        assert_eq!(budget.config, rule);
        // A light the rule's maps were not measured under (a disk) plans
        // exact at every target.
        let disk = |t: Target| plan_eye(&t, rule, "DiskLight", false);
        let loose = disk(Target::new(Some(EYE_RULE_ERROR), None).unwrap());
        assert!(matches!(loose.config, MethodConfig::Exact(_)));
        assert!(loose.decisions[0].why.contains("not under a DiskLight"));
        let budget = disk(Target::new(None, Some(1.0)).unwrap());
        assert!(matches!(budget.config, MethodConfig::Exact(_)));
    }

    #[test]
    fn targets_are_checked() {
        assert!(Target::new(Some(0.0), None).is_err());
        assert!(Target::new(Some(f64::NAN), None).is_err());
        assert!(Target::new(None, Some(-1.0)).is_err());
        assert!(Target::new(Some(0.01), Some(1.0)).is_err());
    }
}
