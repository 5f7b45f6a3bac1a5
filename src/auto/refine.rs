//! A planned call checked against its own error estimate, and run again
//! until the estimate meets the target (`ss.Auto(error=e)`).
//!
//! The plan's settings come from errors measured on the calibration scenes
//! (docs/accuracy.md); a scene unlike them can miss the target (the held-out
//! fence of slats and the blinds took 0.026 and 0.033 for a target of 0.01).
//! After the planned call runs, its estimate (exact rays at a random subset
//! of the pixels, `crate::error_estimate`) is read against the target: the
//! target is met when the estimate's 95% interval lies within it (its upper
//! end at most e), or when no drawn pixel is in shadow (nothing to err on).
//! Otherwise the call runs again:
//!
//! * a map setting: `exact` with the samples the plan's law gives
//!   (the map methods' error does not fall predictably with their settings
//!   on a scene unlike the calibration ones; `exact`'s does);
//! * `exact` with n samples: n (high / e)^2 and at least 2n, high the
//!   interval's upper end
//!   (the law error ∝ 1/sqrt(n) of a random sample), rounded up to a
//!   near-square stratification (a prime count is stratified along one
//!   axis only: `LightShape::square_count`). A stratified sample's
//!   error mostly falls faster (n^-0.7 on the eye scenes: the count then
//!   overshoots), but not everywhere: on the held-out blinds, slats
//!   aliasing with the sample grid, the estimate fell as n^-0.3 from 144
//!   to 877 samples, and a second run followed.
//!
//! At most `MAX_REFINES` runs follow the planned one, and one more where
//! that was an `exact` pilot below the law's count (the eye view's
//! `plan::EYE_PILOT`). `exact`'s estimate
//! compares it with four times its samples, so `MAX_SAMPLES / 4` is the
//! most a refinement asks for; a target out of reach there is reported as
//! missed, not promised.

use super::plan::{exact_samples, square_samples, Decision, MAX_REFINED_SAMPLES};
use crate::error::Result;
use crate::error_estimate::ErrorEstimate;
use crate::methods::{ExactConfig, MethodConfig};

/// Runs after the planned one, at most.
pub const MAX_REFINES: usize = 2;
/// Whether `e` shows the target `target` met: the interval's upper end
/// within it, or no drawn pixel in shadow.
pub fn met(target: f64, e: &ErrorEstimate) -> bool {
    e.shadowed == 0 || e.high <= target
}

/// The setting to run after `ran` missed `target` by its estimate `e`
/// (module docs), with the decision that says why; None where nothing
/// more can be done (`exact` at `MAX_REFINED_SAMPLES`).
pub fn next(
    target: f64,
    ran: &MethodConfig,
    e: &ErrorEstimate,
    law: f64,
) -> Option<(MethodConfig, Decision)> {
    let missed = format!(
        "the estimate {:.4} (95% interval up to {:.4}) misses the target {target}",
        e.error, e.high
    );
    let (samples, how) = match ran.kernel().rays() {
        Some((samples, ..)) => {
            if samples >= MAX_REFINED_SAMPLES {
                return None;
            }
            // At least twice the samples: a miss by a hair would otherwise
            // creep (crowd at 320x240 went 16 -> 25 -> 30, each run paying
            // its BVH and estimate again), and doubling bounds the runs
            // replaced by the last one's time.
            let grown = (samples as f64 * (e.high / target).powi(2)).max(2.0 * samples as f64);
            let mut n = square_samples(
                (grown.ceil() as u32).clamp(samples + 1, MAX_REFINED_SAMPLES),
                MAX_REFINED_SAMPLES,
            );
            // A run below the law's count (the eye view's pilot) grows to
            // at most that count: the law is fitted to the widest
            // penumbrae, and a 16-sample estimate extrapolated by 1/sqrt(n)
            // overshoots (bunny_on_slab: 169 samples for 0.01, where 144
            // measure 0.0055).
            let law_n = exact_samples(law, target);
            if samples < law_n {
                n = n.min(law_n);
            }
            (
                n,
                format!(
                    "{samples} samples times ({:.4}/{target})^2: error about c/sqrt(samples)",
                    e.high
                ),
            )
        }
        None => {
            let n = exact_samples(law, target);
            (
                n,
                format!("the maps' error does not fall predictably with their settings; exact's law {law}/sqrt(samples)"),
            )
        }
    };
    let cfg = MethodConfig::Exact(ExactConfig::of(samples));
    let why = format!("{missed}: exact with {samples} samples a pixel ({how})");
    Some((
        cfg,
        Decision {
            name: "refine",
            taken: true,
            why,
        },
    ))
}

/// The verdict on the last run's estimate, appended to the plan.
pub fn verdict(target: f64, e: &ErrorEstimate) -> Decision {
    let why = if e.shadowed == 0 {
        format!("no drawn pixel is in shadow: nothing to err on (target {target})")
    } else if e.high <= target {
        format!(
            "within the target {target}: the estimate's 95% interval ends at {:.4}",
            e.high
        )
    } else {
        format!(
            "the target {target} is not met: the estimate's 95% interval ends at {:.4}, and \
             exact at {MAX_REFINED_SAMPLES} samples (or {MAX_REFINES} refinements) is the most \
             the planner runs",
            e.high
        )
    };
    Decision {
        name: "target",
        taken: met(target, e),
        why,
    }
}

/// The planned call `first` (its output and the config that ran, which
/// took `first_seconds`), run again by `run` while its estimate
/// (`estimate_of`) misses `target`; the decisions go to `decisions`.
/// Returns the last output and config, and the seconds spent on the runs
/// it replaced (0 when the first was kept).
pub fn refined<T>(
    target: f64,
    law: f64,
    (first, first_seconds): ((T, MethodConfig), f64),
    decisions: &mut Vec<Decision>,
    estimate_of: impl Fn(&T) -> Option<ErrorEstimate>,
    mut run: impl FnMut(&MethodConfig) -> Result<(T, MethodConfig)>,
) -> Result<(T, MethodConfig, f64)> {
    let (mut out, mut ran) = first;
    let (mut replaced, mut last) = (0.0, first_seconds);
    let pilot =
        matches!(ran.kernel().rays(), Some((samples, ..)) if samples < exact_samples(law, target));
    for _ in 0..MAX_REFINES + pilot as usize {
        let Some(e) = estimate_of(&out) else { break };
        if met(target, &e) {
            break;
        }
        let Some((cfg, d)) = next(target, &ran, &e, law) else {
            break;
        };
        decisions.push(d);
        let t = std::time::Instant::now();
        (out, ran) = run(&cfg)?;
        replaced += last;
        last = t.elapsed().as_secs_f64();
    }
    if let Some(e) = estimate_of(&out) {
        decisions.push(verdict(target, &e));
    }
    Ok((out, ran, replaced))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(error: f64, high: f64, shadowed: usize) -> ErrorEstimate {
        ErrorEstimate {
            error,
            low: 0.0,
            high,
            traced: 128,
            shadowed,
            samples: 256,
            seconds: 0.0,
        }
    }

    #[test]
    fn met_by_the_upper_end_or_by_no_shadow() {
        assert!(met(0.01, &estimate(0.008, 0.0099, 10)));
        assert!(!met(0.01, &estimate(0.008, 0.0101, 10)));
        assert!(met(0.01, &estimate(0.0, 1.0, 0)));
    }

    #[test]
    fn exact_grows_by_the_square_of_the_miss_and_stops_at_the_cap() {
        let ran = MethodConfig::Exact(ExactConfig::of(100));
        let (cfg, d) = next(0.01, &ran, &estimate(0.015, 0.02, 10), 0.1).unwrap();
        assert_eq!(cfg, MethodConfig::Exact(ExactConfig::of(400)));
        assert_eq!(d.name, "refine");
        // A miss by a hair still adds samples.
        let (cfg, _) = next(0.01, &ran, &estimate(0.01, 0.010_000_1, 10), 0.1).unwrap();
        assert!(matches!(cfg, MethodConfig::Exact(ExactConfig { samples, .. }) if samples > 100));
        let big = MethodConfig::Exact(ExactConfig::of(MAX_REFINED_SAMPLES / 2));
        // (A law of 1.0 asks for the cap at 0.001: no pilot's bound.)
        let (cfg, _) = next(0.001, &big, &estimate(0.5, 0.6, 10), 1.0).unwrap();
        assert_eq!(
            cfg,
            MethodConfig::Exact(ExactConfig::of(MAX_REFINED_SAMPLES))
        );
        let top = MethodConfig::Exact(ExactConfig::of(MAX_REFINED_SAMPLES));
        assert!(next(0.001, &top, &estimate(0.5, 0.6, 10), 0.1).is_none());
    }

    #[test]
    fn a_pilot_grows_to_at_most_the_law_count() {
        // The law asks 100 for 0.01; a 16-sample pilot missing by 4x would
        // grow to 256 by its own estimate, and stops at 100.
        let pilot = MethodConfig::Exact(ExactConfig::of(16));
        let (cfg, _) = next(0.01, &pilot, &estimate(0.03, 0.04, 10), 0.1).unwrap();
        assert_eq!(cfg, MethodConfig::Exact(ExactConfig::of(100)));
        // Missing by less, it grows by its estimate: 16 (0.017 / 0.01)² = 46.2,
        // rounded up to 7 x 7.
        let (cfg, _) = next(0.01, &pilot, &estimate(0.015, 0.017, 10), 0.1).unwrap();
        assert_eq!(cfg, MethodConfig::Exact(ExactConfig::of(49)));
    }

    #[test]
    fn maps_that_miss_go_to_exact_by_the_law() {
        let ran = MethodConfig::Ssm(Default::default());
        let (cfg, _) = next(0.01, &ran, &estimate(0.05, 0.08, 10), 0.1).unwrap();
        assert_eq!(cfg, MethodConfig::Exact(ExactConfig::of(100)));
    }

    /// The loop from `first` (its estimate and the config that ran), each
    /// run answering `reply`: the output, config and seconds replaced, the
    /// configs run and the decisions.
    #[allow(clippy::type_complexity)]
    fn looped(
        first: (ErrorEstimate, MethodConfig),
        reply: ErrorEstimate,
    ) -> (
        (ErrorEstimate, MethodConfig, f64),
        Vec<MethodConfig>,
        Vec<Decision>,
    ) {
        let (mut d, mut runs) = (vec![], vec![]);
        let out = refined(
            0.01,
            0.1,
            (first, 1.0),
            &mut d,
            |e| Some(*e),
            |cfg| {
                runs.push(*cfg);
                Ok((reply, *cfg))
            },
        )
        .unwrap();
        (out, runs, d)
    }

    fn samples(runs: &[MethodConfig]) -> Vec<u32> {
        runs.iter()
            .map(|c| match c {
                MethodConfig::Exact(e) => e.samples,
                _ => 0,
            })
            .collect()
    }

    #[test]
    fn the_loop_reruns_until_met_and_counts_what_it_replaced() {
        let pilot = MethodConfig::Exact(ExactConfig::of(16));
        let ((out, ran, replaced), runs, d) = looped(
            (estimate(0.03, 0.04, 10), pilot),
            estimate(0.005, 0.008, 10),
        );
        // The pilot's estimate asks 256; the law's 100 caps it.
        assert_eq!(samples(&runs), [100]);
        assert_eq!(ran, runs[0]);
        assert_eq!(out.high, 0.008);
        assert_eq!(replaced, 1.0);
        let names: Vec<_> = d.iter().map(|d| d.name).collect();
        assert_eq!(names, ["refine", "target"]);
        assert!(d[1].taken);
        // Never met: bounded by MAX_REFINES, and the verdict says so. A
        // pilot (16 samples, under the law's 100) gets one run more: 64,
        // then the law's 100, then 400.
        let never = estimate(0.015, 0.02, 10);
        let (_, runs, d) = looped((never, pilot), never);
        assert_eq!(runs.len(), MAX_REFINES + 1);
        assert_eq!(samples(&runs), [64, 100, 400]);
        assert!(!d.last().unwrap().taken);
        // A first run at the law's count is no pilot: MAX_REFINES runs.
        let law = MethodConfig::Exact(ExactConfig::of(100));
        let (_, runs, _) = looped((never, law), never);
        assert_eq!(samples(&runs), [400, 1600]);
        // At the cap nothing more is run.
        let mut d = vec![];
        let top = MethodConfig::Exact(ExactConfig::of(MAX_REFINED_SAMPLES));
        let first = (estimate(0.5, 0.6, 10), top);
        let (_, _, replaced) = refined(
            0.01,
            0.1,
            (first, 1.0),
            &mut d,
            |e| Some(*e),
            |_| panic!("ran past the cap"),
        )
        .unwrap();
        assert_eq!(replaced, 0.0);
        assert_eq!(d.len(), 1);
        assert!(!d[0].taken);
    }
}
