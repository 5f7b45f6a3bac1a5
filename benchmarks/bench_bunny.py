"""What accuracy costs in time: soft shadow maps against Mitsuba's ray_test.

    python benchmarks/bench_bunny.py [--resolutions 128 256 512] [--repeats 9]
                                     [--out docs/benchmarks/bunny.md] [--no-write]

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
run, on the machine at hand.

Prints the markdown table and writes it to ``docs/benchmarks/bunny.md`` (or
``--out``) with a header naming the command, the machine and the date
(``--no-write``: print only). The reference is cached in
``.cache/references/`` like the tests' (delete it to recompute).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from _report import CACHE, DOCS, Report, add_output_arguments, command_line, describe, runs

import softshadow as ss
from softshadow import metrics, reference, scenes
from softshadow.experiments.points import median_seconds as median_time
from softshadow.reference.cache import cached_reference_map

SCENE = "bunny_floating"
MITSUBA_SAMPLES = (4, 16, 64, 256)
EXACT_SAMPLES = (16, 64, 256)


def mitsuba_at_equal_error(err, mi):
    """Mitsuba's time at error `err`, interpolated log-log in (error, time)."""
    e = np.array([m[1] for m in mi])
    t = np.array([m[2] for m in mi])  # ray_test alone
    order = np.argsort(e)
    le, lt = np.log(e[order]), np.log(t[order])
    return float(np.exp(np.interp(np.log(err), le, lt, left=np.nan, right=np.nan))), (err < e.min() or err > e.max())


def compared(t: float, err: float, mi) -> tuple[str, str]:
    """The equal-error Mitsuba time and the ratio, as table cells."""
    t_mi, extrapolated = mitsuba_at_equal_error(err, mi)
    if not np.isfinite(t_mi):
        return "n/a" + (" (outside the measured range)" if extrapolated else ""), "n/a"
    return f"{t_mi * 1e3:.1f}", f"{t / t_mi:.2f}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[128, 256, 512])
    p.add_argument("--repeats", type=int, default=9)
    p.add_argument("--reference-samples", type=int, default=1024)
    add_output_arguments(p, DOCS / "bunny.md")
    a = p.parse_args(argv)

    report = Report("Accuracy against time: the floating bunny", command_line(__file__, argv))
    scene, light = scenes.bunny_floating()
    occluders = list(scene.occluders)
    rscene = reference.ReferenceScene(occluders)
    report.line(
        "| map | method | samples | time (ms) | error | Mitsuba ray_test time at equal error (ms) "
        "| SSM time / Mitsuba ray_test time | Mitsuba whole call (ms) |"
    )
    report.line("|---|---|---|---|---|---|---|---|")
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
        ref = cached_reference_map(SCENE, base, occluders, samples=a.reference_samples, cache=CACHE)

        def check(sm: ss.ShadowMap, base=base, res=res) -> ss.ShadowMap:
            if tuple(sm.extent) != tuple(base.extent):
                raise SystemExit(f"{res}², {describe(sm)}: fitted extent {sm.extent} differs from {base.extent}")
            return sm

        mi = []
        for k in MITSUBA_SAMPLES:
            ts, whole = [], []
            for rep in range(max(3, a.repeats // 3)):
                v = reference.reference_map(base, rscene, samples=k, seed=rep)
                ts.append(rscene.last_stats.trace_seconds)
                whole.append(rscene.last_stats.total_seconds)
            mi.append((k, metrics.shadow_error(v, ref), float(np.median(ts)), float(np.median(whole))))
        for sm, t in maps.values():
            err = metrics.shadow_error(check(sm).visibility, ref)
            t_mi, ratio = compared(t, err, mi)
            report.line(f"| {res}² | {describe(sm)} | - | {t * 1e3:.1f} | {err:.4f} | {t_mi} | {ratio} | |")
        for occ in (res, res // 2):

            def run_bitmask(res=res, occ=occ):
                return ss.soft_shadow_map(
                    scene, light, resolution=res, method="bitmask", samples=256, occluder_resolution=occ
                )

            t = median_time(run_bitmask, max(3, a.repeats // 3))
            sm = check(run_bitmask())
            err = metrics.shadow_error(sm.visibility, ref)
            t_mi, ratio = compared(t, err, mi)
            report.line(f"| {res}² | {describe(sm)} | - | {t * 1e3:.1f} | {err:.4f} | {t_mi} | {ratio} | |")
        for k in EXACT_SAMPLES:

            def run_exact(k=k, res=res):
                return ss.soft_shadow_map(scene, light, resolution=res, method="exact", samples=k)

            t = median_time(run_exact, max(3, a.repeats // 3))
            sm = check(run_exact())
            err = metrics.shadow_error(sm.visibility, ref)
            report.line(f"| {res}² | {describe(sm)} | {sm.method.samples} | {t * 1e3:.1f} | {err:.4f} | | | |")
        for k, err, t, whole in mi:
            report.line(f"| {res}² | Mitsuba ray_test | {k} | {t * 1e3:.1f} | {err:.4f} | | | {whole * 1e3:.1f} |")

    if not a.no_write:
        few = max(3, a.repeats // 3)
        report.write(
            a.out,
            intro=(
                "The bunny 1 unit tall floating 1 above the floor (`softshadow.scenes.bunny_floating()`), "
                "light 1×1 at distance 4. softshadow's times are end to end from meshes on all cores: medians "
                f"of {runs(a.repeats)} after a warm-up for `ssm`, of {few} for `bitmask` (its default hierarchy) "
                f"and `exact`. Mitsuba's are medians of {runs(few)} per sample count of `ray_test` alone, with "
                "the rays already in Dr.Jit arrays, and, in the last column, of the whole `softshadow.reference` "
                "call from numpy points, whose numpy ray set-up dominates. Errors are the paper's §4.2.1 metric "
                f"(mean |V − V_ref| over the texels in umbra or penumbra) against a {a.reference_samples}-sample "
                "Mitsuba reference. Mitsuba's time at a row's error is interpolated log-log between its sample "
                "counts (n/a outside them); the ratio is softshadow's time over that time, below 1 where "
                "softshadow is faster."
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
