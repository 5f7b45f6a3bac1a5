"""What the occluder hierarchy saves, and what it costs in error.

    python benchmarks/bench_hierarchy.py [--resolutions 256 512] [--repeats 3]
        [--scenes bunny_floating bunny_on_floor two_spheres torus]

For each scene and resolution (occluder maps at the output's resolution, two
layers, bitmask with 256 samples): the time end to end from meshes with
``hierarchy=False`` and with the default (``True``), medians of --repeats runs
taken alternately in one run, their errors (the paper's §4.2.1 metric)
against a 1024-sample Mitsuba reference, and the mean and largest change the
hierarchy makes. Prints a markdown table.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import softshadow as ss
from softshadow import metrics, reference, scenes


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[256, 512])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="+", default=["bunny_floating", "bunny_on_floor", "two_spheres", "torus"])
    p.add_argument("--reference-samples", type=int, default=1024)
    a = p.parse_args()

    cpu = platform.processor() or platform.machine()
    print(f"# bitmask, 256 samples, two layers; {cpu}, {os.cpu_count()} cores, Mitsuba {reference.variant()}")
    print()
    print("| scene | map | time off (ms) | time on (ms) | speed-up | error off | error on | mean change | max change |")
    print("|---|---|---|---|---|---|---|---|---|")
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
            ref = reference.reference_map(maps[False], scene.occluders, samples=a.reference_samples, seed=12345)
            err = {h: metrics.shadow_error(maps[h].visibility, ref) for h in (False, True)}
            t_off, t_on = (float(np.median(times[h])) * 1e3 for h in (False, True))
            change = np.abs(maps[True].visibility - maps[False].visibility)
            print(
                f"| {name} | {res}² | {t_off:.0f} | {t_on:.0f} | {t_off / t_on:.2f}x | {err[False]:.4f} "
                f"| {err[True]:.4f} | {change.mean():.4f} | {change.max():.3f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
