"""The eye-view planner's two constants (src/auto/plan.rs), fitted on the
calibration scenes of ``softshadow.scenes.as_built`` only (the held-out ones
judge them, docs/accuracy.md):

* ``EYE_RULE_ERROR``: the largest upper end of the rule maps' error estimate
  (``ss.Auto()``);
* ``EYE_EXACT``: the largest upper end of ``exact``'s error estimate at
  ``--samples`` samples, times sqrt(samples) (the law error = c / sqrt(n)).

The plan is checked against the estimate after each run (src/auto/refine.rs),
so what is fitted is what the estimate shows, drawn as the plan draws it
(``estimate_error="fixed"``: 1024 pixels, the same on any machine); the true
error against the Mitsuba reference is printed beside it.

    python benchmarks/fit_eye_plan.py
"""

from __future__ import annotations

import argparse
import math

from _report import CACHE, DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference.cache import cached_reference_image
from softshadow.scenes.as_built import CALIBRATION, SCENES


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--samples", type=int, default=64)
    add_output_arguments(p, DOCS / "eye_plan_fit.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"The eye-view planner's constants ({res[0]}×{res[1]}, calibration scenes)", command_line(__file__))
    report.line(
        "| scene | rule: true error | rule: estimate (upper end) | "
        f"exact {args.samples}: true error | exact {args.samples}: estimate (upper end) | upper end × √n |"
    )
    report.line("|---|---|---|---|---|---|")
    rule_worst, exact_worst = (0.0, ""), (0.0, "")
    root = math.sqrt(args.samples)
    for name in CALIBRATION:
        scene, light, cam = SCENES[name](res)
        ref = cached_reference_image(name, scene, light, cam, samples=1024, cache=CACHE)
        rule = ss.render(scene, light, cam, method=ss.Auto(), estimate_error="fixed")
        exact = ss.render(scene, light, cam, method=ss.Exact(samples=args.samples), estimate_error="fixed")
        r, x = rule.error_estimate, exact.error_estimate
        rule_worst = max(rule_worst, (r.interval[1], name))
        exact_worst = max(exact_worst, (x.interval[1] * root, name))
        report.line(
            f"| {name} | {compare_images(rule, ref).shadow_error:.4f} | {r.error:.4f} ({r.interval[1]:.4f}) "
            f"| {compare_images(exact, ref).shadow_error:.4f} | {x.error:.4f} ({x.interval[1]:.4f}) "
            f"| {x.interval[1] * root:.3f} |"
        )
    report.line()
    report.line(f"EYE_RULE_ERROR at least {rule_worst[0]:.3f} ({rule_worst[1]})")
    report.line(f"EYE_EXACT at least {exact_worst[0]:.3f} ({exact_worst[1]})")
    if not args.no_write:
        report.write(
            args.out,
            intro=(
                "Fitted on the calibration scenes only; the held-out ones are judged in "
                "docs/benchmarks/scenes_320x240.md. References: 1024-sample Mitsuba renders "
                "(`softshadow.reference.render_visibility`, cached)."
            ),
        )


if __name__ == "__main__":
    main()
