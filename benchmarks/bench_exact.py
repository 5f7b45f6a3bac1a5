"""`exact` per shadow ray against Mitsuba's ray_test, on the study's scenes.

    python benchmarks/bench_exact.py [--resolution 256] [--samples 256]
        [--repeats 5] [--scenes ...] [--out docs/benchmarks/exact.md] [--no-write]

For each scene, in one run and alternating (a load change hits both): the
light view's `exact` at --samples rays per receiver, end to end from meshes,
and Mitsuba's `ray_test` with as many stratified rays per receiver (the
trace alone, the rays already in Dr.Jit arrays). *Rays* counts every
receiver texel's --samples rays, traced or not: `exact` answers the rays of
a receiver whose shaft meets no occluder without tracing them, Mitsuba
traces them all. Errors are the paper's §4.2.1 metric against a 1024-sample
Mitsuba reference (cached in ``.cache/references/``); at equal samples both
converge alike. Times are medians of --repeats.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from _report import CACHE, DOCS, Report, add_output_arguments, command_line, runs
from bench_speed import STUDY, median_seconds

import softshadow as ss
from softshadow import metrics, reference, scenes
from softshadow.reference.cache import cached_reference_map


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--scenes", nargs="+", default=list(STUDY))
    add_output_arguments(p, DOCS / "exact.md")
    a = p.parse_args(argv)

    report = Report("`exact` against Mitsuba's ray_test", command_line(__file__, argv))
    report.line(
        "| scene | receivers | exact (ms) | exact error | Mitsuba (ms) | Mitsuba error "
        "| exact M rays/s | Mitsuba M rays/s | Mitsuba time / exact time |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|")
    res, k = a.resolution, a.samples
    for name in a.scenes:
        scene, light = scenes.SCENES[name]()
        base = ss.soft_shadow_map(scene, light, resolution=res)
        ref = cached_reference_map(name, base, list(scene.occluders), samples=1024, cache=CACHE)
        rscene = reference.ReferenceScene(scene.occluders)
        receivers = int(np.isfinite(base.receiver_depth).sum())

        def run(scene: ss.Scene = scene, light: ss.RectLight = light, extent: object = base.extent) -> ss.ShadowMap:
            return ss.soft_shadow_map(scene, light, resolution=res, extent=extent, method=ss.Exact(samples=k))

        run()  # warm-up
        ts, ms, e_ss, e_mi = [], [], 0.0, 0.0
        for rep in range(a.repeats):
            t, sm = median_seconds(run, 1)
            ts.append(t)
            e_ss = metrics.shadow_error(sm.visibility, ref)
            v = reference.reference_map(base, rscene, samples=k, seed=100 + rep)
            stats = rscene.last_stats
            assert stats is not None  # set by every visibility query
            ms.append(stats.trace_seconds)
            e_mi = metrics.shadow_error(v, ref)
        t, m = float(np.median(ts)), float(np.median(ms))
        rays = receivers * k / 1e6
        report.line(
            f"| {name} | {receivers} | {t * 1e3:.1f} | {e_ss:.4f} | {m * 1e3:.1f} | {e_mi:.4f} "
            f"| {rays / t:.1f} | {rays / m:.1f} | {m / t:.2f} |"
        )
    report.line("")
    report.line(f"{res}² light view, {k} rays per receiver; medians of {runs(a.repeats)}.")
    if not a.no_write:
        report.write(
            a.out,
            intro=(
                "The light view's `exact` (SAH BVH, one receiver's rays culled by their shaft, a subtree "
                "shadow cache; docs/methods/exact.md) against Mitsuba's `ray_test` with the same number of "
                "stratified rays per receiver texel. Rays per second count every texel's rays, traced or not."
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
