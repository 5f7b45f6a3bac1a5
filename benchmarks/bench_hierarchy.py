"""What the occluder hierarchy saves, and what it costs in error.

    python benchmarks/bench_hierarchy.py [--resolutions 256 512] [--repeats 3]
        [--scenes bunny_floating bunny_on_floor two_spheres torus]
        [--out docs/benchmarks/hierarchy.md] [--no-write]

For each scene and resolution (occluder maps at the output's resolution, two
layers, bitmask with 256 samples): the time end to end from meshes with
``hierarchy=False`` and with the default (``True``), medians of --repeats runs
taken alternately in one run, their errors (the paper's §4.2.1 metric)
against a 1024-sample Mitsuba reference, and the mean and largest change the
hierarchy makes.

Prints the markdown table and writes it to ``docs/benchmarks/hierarchy.md``
(or ``--out``) with a header naming the command, the machine and the date
(``--no-write``: print only). The references are cached in
``.cache/references/`` like the tests' (delete it to recompute).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from _report import CACHE, DOCS, Report, add_output_arguments, command_line, runs

import softshadow as ss
from softshadow import metrics, scenes
from softshadow.reference.cache import cached_reference_map


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[256, 512])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="+", default=["bunny_floating", "bunny_on_floor", "two_spheres", "torus"])
    p.add_argument("--reference-samples", type=int, default=1024)
    add_output_arguments(p, DOCS / "hierarchy.md")
    a = p.parse_args(argv)

    report = Report("The occluder hierarchy off and on", command_line(__file__, argv))
    report.line(
        "| scene | map | time off (ms) | time on (ms) | speed-up | error off | error on | mean change | max change |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|")
    for name in a.scenes:
        scene, light = scenes.SCENES[name]()
        for res in a.resolutions:
            kw = dict(resolution=res, method="bitmask", samples=256, passes=2)
            times: dict[bool, list[float]] = {False: [], True: []}
            maps = {}
            for _ in range(a.repeats):
                for h in (False, True):
                    t = time.perf_counter()
                    maps[h] = ss.soft_shadow_map(scene, light, hierarchy=h, **kw)
                    times[h].append(time.perf_counter() - t)
            if [maps[h].method.hierarchy for h in (False, True)] != [False, True]:
                raise SystemExit(f"{name} {res}²: ran {maps[False].method!r} and {maps[True].method!r}")
            occluders = list(scene.occluders)
            ref = cached_reference_map(name, maps[False], occluders, samples=a.reference_samples, cache=CACHE)
            err = {h: metrics.shadow_error(maps[h].visibility, ref) for h in (False, True)}
            t_off, t_on = (float(np.median(times[h])) * 1e3 for h in (False, True))
            change = np.abs(maps[True].visibility - maps[False].visibility)
            report.line(
                f"| {name} | {res}² | {t_off:.0f} | {t_on:.0f} | {t_off / t_on:.2f}x "
                f"| {err[False]:.4f} | {err[True]:.4f} | {change.mean():.4f} | {change.max():.3f} |"
            )

    if not a.no_write:
        report.write(
            a.out,
            intro=(
                '`method="bitmask", samples=256, passes=2`, occluder maps at the output\'s resolution, with '
                f"`hierarchy=False` and `hierarchy=True` (the default): medians of {runs(a.repeats)} each, end to "
                "end from meshes on all cores, off and on timed alternately in one run. Errors are the paper's "
                "§4.2.1 metric (mean |V − V_ref| over the texels in umbra or penumbra) against "
                f"{a.reference_samples}-sample Mitsuba references; the changes are |V_on − V_off| over all texels. "
                "How the hierarchy works: [bitmask](../methods/bitmask.md#occluder-hierarchy)."
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
