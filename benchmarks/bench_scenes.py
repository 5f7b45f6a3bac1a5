"""Accuracy on scenes built the way users build them: every method's error
over the pixels the reference shadows, its acne and leak rates, on the
calibration and held-out scenes of ``softshadow.scenes.as_built``.

    python benchmarks/bench_scenes.py [--resolution 320 240] [--scenes ...] [--methods ...] [--no-write]

For each scene, a Mitsuba reference (``--reference-samples`` stratified light
samples a pixel, cached in ``.cache/references/``) and one call per method of
``METHODS`` end to end from the meshes (time: one run after a warm-up of the
scene, wall clock; speed lives in ``bench_eye.py``). Per call,
``softshadow.metrics.compare_images``: ``shadow_error`` (mean |V - V_ref|
over the matched pixels the reference shadows), ``mean_abs`` (over every
matched pixel), ``acne`` and ``leak`` (fractions of the matched pixels),
``grain`` (per-pixel noise over the reference's own, on its penumbra);
then the same call with ``estimate_error=True``: its ``error_estimate``
against the measured error, and its share of the call's time.
Writes ``docs/benchmarks/scenes_<W>x<H>.md``; the summary gives each method's
worst scene of each set.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from _report import CACHE, DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference.cache import cached_reference_image
from softshadow.scenes.as_built import CALIBRATION, HELD_OUT, SCENES

#: The calls measured, by label: the default call (no method given),
#: every method family with its defaults, and ``exact`` behind a probe.
METHODS: dict[str, Any] = {
    "default": None,
    "ssm": ss.Ssm(),
    "bitmask": ss.Bitmask(),
    "exact": ss.Exact(),
    "exact+probe": ss.Exact(probe=16),
    "PCSS": ss.PCSS(),
    "Smoothies": ss.Smoothies(),
    "ShadowMapping+PCF3": ss.ShadowMapping(filter=ss.PCF(size=3)),
    "Auto(error=0.01)": ss.Auto(error=0.01),
    "Auto(error=0.005)": ss.Auto(error=0.005),
}


def call(method: Any, scene: Any, light: Any, cam: Any, **kw: Any) -> Any:
    if method is None:
        return ss.render(scene, light, cam, **kw)
    return ss.render(scene, light, cam, method=method, **kw)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    # 4096: at 1024 the reference is itself 0.005 off a 4096-sample one over
    # the shadows of fence_slats and blinds, too coarse to judge
    # Auto(error=0.005) (measured: 0.0053 and 0.0046).
    p.add_argument("--reference-samples", type=int, default=4096)
    p.add_argument("--scenes", nargs="*", default=list(SCENES))
    p.add_argument("--methods", nargs="*", default=list(METHODS))
    add_output_arguments(p, DOCS / "scenes.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    if args.out == DOCS / "scenes.md":
        args.out = DOCS / f"scenes_{res[0]}x{res[1]}.md"
    report = Report(f"Scenes as users build them ({res[0]}×{res[1]})", command_line(__file__))
    worst: dict[tuple[str, str], list[float]] = {}
    ratios: dict[str, list[tuple[float, float, float]]] = {}
    for name in args.scenes:
        scene, light, cam = SCENES[name](res)
        which = "calibration" if name in CALIBRATION else "held out" if name in HELD_OUT else "?"
        ref = cached_reference_image(name, scene, light, cam, samples=args.reference_samples, cache=CACHE)
        report.line(f"## {name} ({which})")
        report.line()
        report.line(
            f"{scene.triangle_count} triangles in {len(scene.meshes)} meshes; {type(light).__name__}; "
            f"the reference shadows {(ref.mask & (ref.visibility < 0.999)).sum() / max(ref.mask.sum(), 1):.1%} "
            f"of the pixels that see a surface."
        )
        report.line()
        report.line(
            "| call | error over shadowed pixels | over all pixels | acne | leaks | grain | time (ms) | ran "
            "| estimate (95% interval) | estimate / error | its share of the call |"
        )
        report.line("|---|---|---|---|---|---|---|---|---|---|---|")
        for label in args.methods:
            try:
                t = time.perf_counter()
                img = call(METHODS[label], scene, light, cam)
                ms = (time.perf_counter() - t) * 1e3
            except (ValueError, RuntimeError) as e:  # a method the scene's light does not take
                report.line(f"| {label} | refused: {str(e).splitlines()[0][:80]} | | | | | | |")
                continue
            c = compare_images(img, ref)
            ran = img.method.name if hasattr(img.method, "name") else str(img.method)
            # The same call with its error estimate (Auto always has one).
            est = (
                img if img.error_estimate is not None else call(METHODS[label], scene, light, cam, estimate_error=True)
            )
            e = est.error_estimate
            share = e.seconds / sum(est.timings.values())
            ratio = f"{e.error / c.shadow_error:.2f}" if c.shadow_error > 0 else "–"
            report.line(
                f"| {label} | {c.shadow_error:.4f} | {c.mean_abs:.4f} | {c.acne:.2%} | {c.leak:.2%} "
                f"| {c.grain:+.4f} | {ms:.0f} | {ran} | {e.error:.4f} ({e.interval[0]:.4f}–{e.interval[1]:.4f}), "
                f"{e.traced} px | {ratio} | {share:.0%} |"
            )
            ratios.setdefault(label, []).append((c.shadow_error, e.error, share))
            w = worst.setdefault((label, which), [0.0, 0.0, 0.0, 0.0])
            w[0], w[1], w[2] = max(w[0], c.shadow_error), max(w[1], c.acne), max(w[2], c.leak)
            w[3] = max(w[3], c.grain)
        report.line()
    report.line("## Summary: each call's worst scene")
    report.line()
    report.line("| call | set | error over shadowed pixels | acne | leaks | grain |")
    report.line("|---|---|---|---|---|---|")
    for (label, which), (e, a, lk, g) in worst.items():
        report.line(f"| {label} | {which} | {e:.4f} | {a:.2%} | {lk:.2%} | {g:+.4f} |")
    report.line()
    report.line("## Summary: the error estimates")
    report.line()
    report.line(
        "| call | scenes with the estimate within 1.5× of the error | worst ratio | median share of the call "
        "| largest share |"
    )
    report.line("|---|---|---|---|---|")
    for label, rs in ratios.items():
        within = [r for r in rs if r[0] > 0 and 1 / 1.5 <= r[1] / r[0] <= 1.5]
        graded = [r[1] / r[0] for r in rs if r[0] > 0]
        worst_ratio = max(graded, key=lambda q: max(q, 1 / q) if q > 0 else float("inf")) if graded else 0.0
        shares = sorted(r[2] for r in rs)
        report.line(
            f"| {label} | {len(within)} of {len(graded)} | {worst_ratio:.2f} | {shares[len(shares) // 2]:.0%} "
            f"| {shares[-1]:.0%} |"
        )
    if args.no_write:
        return
    intro = (
        f"Against {args.reference_samples}-sample Mitsuba references "
        "(`softshadow.reference.render_visibility`). Errors and rates from "
        "`softshadow.metrics.compare_images` over the pixels both renderers see on the same mesh: "
        "*error over shadowed pixels* is the mean |V - V_ref| where the reference occlusion "
        "exceeds 0.001; *over all pixels* counts lit ones too; *acne* is the share of pixels "
        "the reference sees fully lit (V_ref ≥ 0.99) that the call darkens by more than 0.05, "
        "*leaks* the share in the reference umbra (V_ref ≤ 0.01) it lightens by more than 0.05. "
        "Calibration scenes may be fitted to; held-out ones are not (docs/accuracy.md). "
        "*Estimate*: `img.error_estimate` of the same call with `estimate_error=True` (exact rays at a "
        "random subset of the pixels; Auto always has one), its ratio to the error measured against "
        "Mitsuba, and the estimate's share of that call's time."
    )
    report.write(args.out, intro=intro)


if __name__ == "__main__":
    main()
