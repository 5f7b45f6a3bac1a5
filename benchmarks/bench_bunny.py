"""What accuracy costs in time: soft shadow maps against Mitsuba's ray_test.

    python benchmarks/bench_bunny.py [--resolutions 128 256 512] [--repeats 9]

For the bunny floating over the floor (light 1x1 at distance 4, bunny 1 unit
tall), at each resolution: the SSM's time end to end from meshes (one and two
passes, occluder maps at the output's resolution and at 1/2 and 1/4 of it;
median of --repeats runs) and its error (the paper's §4.2.1 metric)
against a 1024-sample Mitsuba reference; Mitsuba's ray_test time (median,
rays already in Dr.Jit arrays: the tracing alone) and error at 4, 16, 64 and 256
samples per texel, and the whole softshadow.reference call (numpy points to
visibility, the numpy ray set-up
included); and the ratio of the SSM's time to Mitsuba's ray_test time at
equal error, Mitsuba's time and error being interpolated log-log between the
measured sample counts (error ~ 1/sqrt(samples), time ~ samples). All in one
run, on the machine at hand. Prints a markdown table.
"""

from __future__ import annotations

import argparse
import os
import platform

import numpy as np

import softshadow as ss
from softshadow import metrics, reference, scenes
from softshadow.experiments.study import median_seconds as median_time

MITSUBA_SAMPLES = (4, 16, 64, 256)
EXACT_SAMPLES = (16, 64, 256)


def mitsuba_at_equal_error(err, mi):
    """Mitsuba's time at error `err`, interpolated log-log in (error, time)."""
    e = np.array([m[1] for m in mi])
    t = np.array([m[2] for m in mi])  # ray_test alone
    order = np.argsort(e)
    le, lt = np.log(e[order]), np.log(t[order])
    return float(np.exp(np.interp(np.log(err), le, lt, left=np.nan, right=np.nan))), (err < e.min() or err > e.max())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[128, 256, 512])
    p.add_argument("--repeats", type=int, default=9)
    p.add_argument("--reference-samples", type=int, default=1024)
    a = p.parse_args()

    scene, light = scenes.bunny_floating()
    rscene = reference.ReferenceScene(scene.occluders)
    cpu = platform.processor() or platform.machine()
    print(f"# bunny floating, {cpu}, {os.cpu_count()} cores, Mitsuba {reference.variant()}")
    print()
    print(
        "| map | method | samples | time (ms) | error | Mitsuba ray_test time at equal error (ms) "
        "| SSM time / Mitsuba ray_test time | Mitsuba whole call (ms) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for res in a.resolutions:
        maps = {}
        # (passes, occluder map resolution): the paper's setup shares the
        # output's resolution; coarser occluder maps are the cheap variant.
        variants = [(p, o) for p in (1, 2) for o in (res, res // 2, res // 4) if o >= 32]
        for passes, occ in variants:

            def run(passes=passes, res=res, occ=occ):
                return ss.soft_shadow_map(scene, light, resolution=res, passes=passes, occluder_resolution=occ)

            t = median_time(run, a.repeats)
            maps[(passes, occ)] = (run(), t)
        base = maps[(2, res)][0]
        ref = reference.reference_map(base, rscene, samples=a.reference_samples, seed=12345)
        mi = []
        for k in MITSUBA_SAMPLES:
            ts, whole = [], []
            for rep in range(max(3, a.repeats // 3)):
                v = reference.reference_map(base, rscene, samples=k, seed=rep)
                ts.append(rscene.last_stats.trace_seconds)
                whole.append(rscene.last_stats.total_seconds)
            mi.append((k, metrics.shadow_error(v, ref), float(np.median(ts)), float(np.median(whole))))
        for (passes, occ), (sm, t) in maps.items():
            err = metrics.shadow_error(sm.visibility, ref)
            t_mi, extrapolated = mitsuba_at_equal_error(err, mi)
            note = " (outside the measured range)" if extrapolated else ""
            ratio = f"{t / t_mi:.2f}" if np.isfinite(t_mi) else "n/a"
            t_mi_s = f"{t_mi * 1e3:.1f}" if np.isfinite(t_mi) else "n/a"
            name = f"ssm, {passes} pass{'es' if passes > 1 else ''}, occluders {occ}²"
            print(f"| {res}² | {name} | - | {t * 1e3:.1f} | {err:.4f} | {t_mi_s}{note} | {ratio} | |")
        for occ in (res, res // 2):

            def run_bitmask(res=res, occ=occ):
                return ss.soft_shadow_map(
                    scene, light, resolution=res, method="bitmask", samples=256, occluder_resolution=occ
                )

            t = median_time(run_bitmask, max(3, a.repeats // 3))
            err = metrics.shadow_error(run_bitmask().visibility, ref)
            t_mi, extrapolated = mitsuba_at_equal_error(err, mi)
            ratio = f"{t / t_mi:.2f}" if np.isfinite(t_mi) else "n/a"
            t_mi_s = f"{t_mi * 1e3:.1f}" if np.isfinite(t_mi) else "n/a"
            name = f"bitmask, 256 samples, occluders {occ}²"
            print(f"| {res}² | {name} | - | {t * 1e3:.1f} | {err:.4f} | {t_mi_s} | {ratio} | |")
        for k in EXACT_SAMPLES:

            def run_exact(k=k, res=res):
                return ss.soft_shadow_map(scene, light, resolution=res, method="exact", samples=k)

            t = median_time(run_exact, max(3, a.repeats // 3))
            err = metrics.shadow_error(run_exact().visibility, ref)
            print(f"| {res}² | exact | {k} | {t * 1e3:.1f} | {err:.4f} | | | |")
        for k, err, t, whole in mi:
            print(f"| {res}² | Mitsuba ray_test | {k} | {t * 1e3:.1f} | {err:.4f} | | | {whole * 1e3:.1f} |")


if __name__ == "__main__":
    main()
