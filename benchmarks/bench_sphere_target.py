"""``Auto(error=target)`` under a sphere light, against Mitsuba: does the
planned ``exact`` meet the target on scenes built as users build them?

    python benchmarks/bench_sphere_target.py [--resolution 80 60] [--targets 0.02 0.01]
        [--mitsuba-samples 1024] [--scenes ...] [--no-write]

Each scene of ``softshadow.scenes.as_built`` with a rectangle light gets, in
its place, the sphere of the disk of the rectangle's area (the radius
sqrt(area/π)) at its centre. A target plans ``exact`` by the eye view's law
(fitted on rectangles, on the calibration scenes) and checks the run's own
error estimate (the sphere's rays with four times the samples at a fixed
draw of pixels), refining where it misses (``auto/refine.rs``). The error is
the headline metric (``softshadow.metrics.compare_images``): mean
|V − V_ref| over the pixels the reference shadows, of those where both see
the same surface point (a silhouette the two place differently is not a
shadow error), against ``render_visibility`` at ``--mitsuba-samples``
(seed 0); the noise column is Mitsuba's own (seed 1 against seed 0), which
the error includes. Acne and leaks as docs/accuracy.md defines them, as
percentages of the compared pixels. Times: one
render each (after a warm-up of ours), Mitsuba's scene loading and JIT
included. The set column says which scenes any rule or constant was fitted
on (calibration) and which judge them (held out).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference import render_visibility
from softshadow.scenes import as_built


def compared(ours: Any, ref: Any) -> tuple[float, float, float]:
    """(mean |ΔV| over the matched pixels the reference shadows, acne, leaks:
    fractions of the matched pixels), ``softshadow.metrics.compare_images``."""
    c = compare_images(ours, ref)
    return c.shadow_error, c.acne, c.leak


def sphere_of(light: Any) -> Any:
    sx, sy = light.size
    return ss.SphereLight(light.center, float(np.sqrt(sx * sy / np.pi)))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(80, 60), metavar=("W", "H"))
    p.add_argument("--targets", type=float, nargs="*", default=[0.02, 0.01])
    p.add_argument("--mitsuba-samples", type=int, default=1024)
    p.add_argument("--scenes", nargs="*", default=list(as_built.SCENES))
    add_output_arguments(p, DOCS / "sphere_target.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"Auto(error=...) under a sphere light against Mitsuba ({res[0]}×{res[1]})", command_line(__file__))
    report.line(
        "| scene | set | sphere radius | Mitsuba noise | target | planned | estimate | error | acne | leaks "
        "| met | time (ms) | Mitsuba (ms) |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    met = total = 0
    for name in args.scenes:
        scene, light, cam = as_built.SCENES[name](res)
        if not isinstance(light, ss.RectLight):
            continue
        sphere = sphere_of(light)
        which = "calibration" if name in as_built.CALIBRATION else "held out"
        t0 = time.perf_counter()
        ref = render_visibility(scene, sphere, cam, samples=args.mitsuba_samples, seed=0)
        mitsuba_ms = (time.perf_counter() - t0) * 1e3
        second = render_visibility(scene, sphere, cam, samples=args.mitsuba_samples, seed=1)
        noise = compared(second, ref)[0]
        for target in args.targets:
            method = ss.Auto(error=target)
            ss.render(scene, sphere, cam, method=method)  # warm-up
            t0 = time.perf_counter()
            img = ss.render(scene, sphere, cam, method=method)
            ms = (time.perf_counter() - t0) * 1e3
            error, acne, leaks = compared(img, ref)
            e = img.error_estimate
            ok = error <= target
            met += ok
            total += 1
            report.line(
                f"| {name} | {which} | {sphere.radius:.3g} | {noise:.4f} | {target:g} | "
                f"{img.method.samples} samples | {e.error:.4f} | {error:.4f} | {acne:.2%} | {leaks:.2%} | "
                f"{'yes' if ok else '**no**'} | {ms:.0f} | {mitsuba_ms:.0f} |"
            )
    report.line("")
    report.line(f"Targets met: {met} of {total}.")
    if not args.no_write:
        report.write(args.out, intro=__doc__.split("\n\n", 2)[2].replace("\n", " ").strip())


if __name__ == "__main__":
    main()
