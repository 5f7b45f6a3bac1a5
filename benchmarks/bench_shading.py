"""Shaded images against Mitsuba's ``direct`` integrator: the error of
``Image.shaded`` and its times, under rectangles, disks, spheres and the sun.

    python benchmarks/bench_shading.py [--resolution 320 240] [--mitsuba-samples 1024]
        [--exact-samples 1024] [--repeats 3] [--scenes ...] [--no-write]

For each scene of ``softshadow.scenes.eye_view.EYE_SCENES`` (the lights' default
emission, 1, and the default albedo, 0.8 grey; the sun of ``city`` made hard,
angular size 0, since Mitsuba's ``directional`` emitter is a delta
direction), the reference is ``softshadow.reference.render_direct`` at
``--mitsuba-samples`` per pixel, seed 0; Mitsuba's own noise is the same
render with seed 1 against it. The error of an image is
``mean|shaded - reference| / mean(reference)`` over the pixels that see a
surface. ``exact`` at ``--exact-samples`` weighs each of its samples by what
it adds to the irradiance (docs/shading.md), so its error is its sampling's
plus the reference's noise; ``V × unshadowed`` is the same visibility with
the light's parts weighted alike (what the map methods other than the
bitmask and the SSM shade with); the default method (``"auto"``) adds its
visibility error; ``bitmask`` (1024 samples) weighs its light samples as
``exact`` its rays, and ``ssm`` (its defaults; rectangles and disks) its
micro-patches, so their error is their visibility's; ``unshadowed`` shows
what the shadows are worth.
Besides each scene's rectangle, the disk of the same area and the sphere of
the same radius at its centre light it too (rows "disk", "sphere"; a sphere
takes ``exact`` only, so no bitmask or ssm). Times: medians of
``--repeats`` renders after a warm-up (the whole ``ss.render`` call, and its
``shading`` stage), Mitsuba's of one render (scene loading and its JIT
included). Prints the table and writes it to ``docs/benchmarks/shading.md``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line, runs

import softshadow as ss
from softshadow.reference import render_direct
from softshadow.scenes.eye_view import EYE_SCENES


def relative_error(ours: np.ndarray, reference: np.ndarray, mask: np.ndarray) -> float:
    """mean |ours - reference| / mean(reference) over ``mask``."""
    return float(np.abs(ours[mask] - reference[mask]).mean() / reference[mask].mean())


def timed_render(scene: Any, light: Any, cam: Any, method: Any, repeats: int) -> tuple[Any, float, float]:
    """The image, and the medians of the render's and its shading stage's seconds."""
    img = ss.render(scene, light, cam, method=method)  # warm-up
    total, shading = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        img = ss.render(scene, light, cam, method=method)
        total.append(time.perf_counter() - t0)
        shading.append(img.timings["shading"])
    return img, statistics.median(total), statistics.median(shading)


def lights_of(light: Any) -> list[tuple[str, Any]]:
    """The scene's light (the sun made hard), and for a rectangle the disk
    of its area and the sphere of that radius at its centre."""
    if isinstance(light, ss.DirectionalLight):
        return [("sun, hard", ss.DirectionalLight(light.direction, light.up, angular_size=0.0))]
    sx, sy = light.size
    r = float(np.sqrt(sx * sy / np.pi))
    return [
        (f"rectangle {sx:g}×{sy:g}", light),
        (f"disk r {r:.3g}", ss.DiskLight(light.center, light.normal, r)),
        (f"sphere r {r:.3g}", ss.SphereLight(light.center, r)),
    ]


def row(report: Report, name: str, kind: str, scene: Any, light: Any, cam: Any, args: Any) -> None:
    """One light's row of the table."""
    t0 = time.perf_counter()
    reference = render_direct(scene, light, cam, samples=args.mitsuba_samples, seed=0)
    mitsuba_seconds = time.perf_counter() - t0
    second = render_direct(scene, light, cam, samples=args.mitsuba_samples, seed=1)
    exact, exact_s, _ = timed_render(scene, light, cam, ss.Exact(samples=args.exact_samples), args.repeats)
    auto, auto_s, shading_s = timed_render(scene, light, cam, "auto", args.repeats)
    m = exact.mask
    plain = exact.unshadowed * exact.visibility[..., None]
    bitmask = ssm = pcss = "–"
    if not isinstance(light, ss.SphereLight):
        b = ss.render(scene, light, cam, method=ss.Bitmask(samples=1024))
        bitmask = f"{relative_error(b.shaded, reference, m):.4f}"
        s = ss.render(scene, light, cam, method="ssm")
        ssm = f"{relative_error(s.shaded, reference, m):.4f}"
        c = ss.render(scene, light, cam, method=ss.PCSS())
        pcss = f"{relative_error(c.shaded, reference, m):.4f}"
    report.line(
        f"| {name} | {kind} | {relative_error(second, reference, m):.4f} | "
        f"{relative_error(exact.shaded, reference, m):.4f} | {relative_error(plain, reference, m):.4f} | "
        f"{exact_s * 1e3:.0f} | {relative_error(auto.shaded, reference, m):.4f} | {auto_s * 1e3:.0f} | "
        f"{shading_s * 1e3:.1f} | {bitmask} | {ssm} | {pcss} | {relative_error(exact.unshadowed, reference, m):.4f} | "
        f"{mitsuba_seconds * 1e3:.0f} |"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--mitsuba-samples", type=int, default=1024)
    p.add_argument("--exact-samples", type=int, default=1024)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="*", default=list(EYE_SCENES))
    add_output_arguments(p, DOCS / "shading.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"Shaded images against Mitsuba's direct integrator ({res[0]}×{res[1]})", command_line(__file__))
    report.line(
        f"| scene | light | Mitsuba noise (seed 1 vs 0) | exact {args.exact_samples}: error | "
        "V × unshadowed: error | time (ms) | auto: error | time (ms) | shading stage (ms) | bitmask: error | "
        "ssm: error | pcss: error | unshadowed: error | Mitsuba direct (ms) |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        scene, light, cam = EYE_SCENES[name](res)
        for kind, lt in lights_of(light):
            row(report, name, kind, scene, lt, cam, args)
    if args.no_write:
        return
    intro = (
        f"Error: mean |shaded − Mitsuba| / mean(Mitsuba) over the pixels that see a surface, against "
        f"`render_direct` at {args.mitsuba_samples} samples a pixel (seed 0); the noise column is the "
        f"same render with seed 1 against it. Our times are medians of {runs(args.repeats)} after a "
        "warm-up; Mitsuba's is one render, scene loading and JIT included. The lights emit 1 and every "
        "mesh's albedo is 0.8; `city`'s sun is made hard (Mitsuba's directional emitter is a delta), so "
        "`exact` casts one ray a pixel there. `V × unshadowed` is exact's visibility with every part of the "
        "light weighted alike (what `smoothies` and `shadow_mapping` shade with; `bitmask`, `ssm` and `pcss` "
        "weigh their light samples, micro-patches and filter cells, docs/shading.md). The disk has the rectangle's "
        "area, the sphere the disk's radius, both at its centre. The shading stage is "
        "`img.timings['shading']` of the `auto` renders (the albedo image, the closed form at every pixel that "
        "sees a surface)."
    )
    report.write(args.out, intro=intro)


if __name__ == "__main__":
    main()
