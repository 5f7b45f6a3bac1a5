"""PCSS's tap budget: error and time against ``max_taps``, the choice of its default.

    python benchmarks/bench_pcss.py [--taps 32 16 8 4] [--repeats 3] [--no-write]

Light view: each study scene at 256² (occluder maps at the output's
resolution), error (the paper's §4.2.1 metric) against a 1024-sample
Mitsuba reference (cached in ``.cache/references/`` like the tests'). Eye
view: each scene of ``softshadow.scenes.eye_view`` at 320×240, mean |V - V_ref|
over the visible pixels against 256-sample ``exact``. Times are medians of
``--repeats``, end to end from the meshes, the tap counts taken alternately
in one run. Writes ``docs/benchmarks/pcss.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import numpy as np
from _report import CACHE, DOCS, Report, add_output_arguments, command_line, runs

import softshadow as ss
from softshadow import metrics, scenes
from softshadow.reference.cache import cached_reference_map
from softshadow.scenes.eye_view import EYE_SCENES


def alternate(fns: dict[int, Any], repeats: int) -> tuple[dict[int, float], dict[int, Any]]:
    times: dict[int, list[float]] = {k: [] for k in fns}
    outs: dict[int, Any] = {}
    for _ in range(repeats):
        for k, fn in fns.items():
            t = time.perf_counter()
            outs[k] = fn()
            times[k].append(time.perf_counter() - t)
    return {k: float(np.median(v)) for k, v in times.items()}, outs


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--taps", type=int, nargs="+", default=[32, 16, 8, 4])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="+", default=["bunny_floating", "bunny_on_floor", "two_spheres", "torus"])
    add_output_arguments(p, DOCS / "pcss.md")
    a = p.parse_args(argv)
    report = Report("PCSS: error and time against max_taps", command_line(__file__, argv))
    head = "| scene | " + " | ".join(f"{t} taps: error (ms)" for t in a.taps) + " |"
    sep = "|---|" + "---|" * len(a.taps)
    report.line("## Light view (256²)")
    report.line()
    report.line(head)
    report.line(sep)
    for name in a.scenes:
        scene, light = scenes.SCENES[name]()
        fns = {
            t: (lambda t=t, s=scene, li=light: ss.soft_shadow_map(s, li, resolution=256, method=ss.PCSS(max_taps=t)))
            for t in a.taps
        }
        sec, outs = alternate(fns, a.repeats)
        ref = cached_reference_map(name, outs[a.taps[0]], list(scene.occluders), samples=1024, cache=CACHE)
        cells = [f"{metrics.shadow_error(outs[t].visibility, ref):.4f} ({sec[t] * 1e3:.0f})" for t in a.taps]
        report.line(f"| {name} | " + " | ".join(cells) + " |")
    report.line()
    report.line("## Eye view (320×240)")
    report.line()
    report.line(head)
    report.line(sep)
    for name, make in EYE_SCENES.items():
        scene, light, cam = make((320, 240))
        ref = ss.render(scene, light, cam, method=ss.Exact(samples=256))
        fns = {
            t: (lambda t=t, s=scene, li=light, c=cam: ss.render(s, li, c, method=ss.PCSS(max_taps=t))) for t in a.taps
        }
        sec, outs = alternate(fns, a.repeats)
        cells = [
            f"{np.abs(outs[t].visibility - ref.visibility)[ref.mask].mean():.4f} ({sec[t] * 1e3:.0f})" for t in a.taps
        ]
        report.line(f"| {name} | " + " | ".join(cells) + " |")
    if not a.no_write:
        report.write(
            a.out,
            intro=(
                f"`ss.PCSS(max_taps=m)`: at most m × m taps per stage per point. Medians of {runs(a.repeats)}, "
                "end to end from the meshes, the tap counts taken alternately in one run. Light-view errors: "
                "the paper's §4.2.1 metric against 1024-sample Mitsuba maps; eye-view errors: mean |V - V_ref| "
                "over the visible pixels against 256-sample `exact`."
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
