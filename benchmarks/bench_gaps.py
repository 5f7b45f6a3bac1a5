"""Accuracy on every surface: bitmask's connected micro-quads (gaps closed)
against its flat micro-patches (gaps open) and the published SSM.

    python benchmarks/bench_gaps.py [--resolution 256] [--repeats 3]
        [--scenes ...] [--out docs/benchmarks/gaps.md] [--no-write]

On the study's four scenes and the hard surfaces of `softshadow.scenes`
(`HARD_SURFACES`: a plate tilted against the light, a slanted receiver, a
fence of thin bars, a box in contact with the floor, a sphere near the light),
at one resolution, two layers: the error (the paper's §4.2.1 metric) against a
1024-sample Mitsuba reference, the mean signed error (> 0: too light) and the
time end to end from meshes (medians of --repeats rounds, each round runs
every setting and the planner once, all cores). The
reference's own noise is the error of a second Mitsuba reference with another
seed against the first, printed beside each scene.

Prints the markdown tables and writes them to ``docs/benchmarks/gaps.md`` (or
``--out``) with a header naming the command, the machine and the date. The
references are cached in ``.cache/references/`` like the tests'.
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

STUDY = ("bunny_floating", "bunny_on_floor", "two_spheres", "torus")
#: The settings compared, by label.
SETTINGS: dict[str, Any] = {
    "auto rule (the probe)": ss.Auto(),
    "ssm": ss.Ssm(),
    "bitmask 256 open": ss.Bitmask(gaps="open"),
    "bitmask 256 open, no hierarchy": ss.Bitmask(gaps="open", hierarchy=False),
    "bitmask 256 closed": ss.Bitmask(),
    "bitmask 256 closed, no hierarchy": ss.Bitmask(hierarchy=False),
    "bitmask 1024 open, no hierarchy": ss.Bitmask(samples=1024, gaps="open", hierarchy=False),
    "bitmask 1024 closed, no hierarchy": ss.Bitmask(samples=1024, hierarchy=False),
    # Occluder maps at twice the output's side (what the planner takes for
    # thin occluders under a tight target).
    "bitmask 1024 closed, no hierarchy, occluder maps 2x": lambda res: ss.Bitmask(
        samples=1024, hierarchy=False, occluder_resolution=2 * res
    ),
}
#: The planner's targets, each against the fastest fixed setting within it.
TARGETS = (0.01, 0.005)


def timed_rounds(
    scene: ss.Scene, light: ss.RectLight, res: int, extent: Any, repeats: int, methods: dict[str, Any]
) -> dict[str, tuple[float, ss.ShadowMap]]:
    """Per label, (median seconds of ``repeats`` runs, the last map). The
    methods run round by round (one run of each per round), so that the
    machine's slow spells fall on every setting alike: the ratios between
    them are what the tables quote."""
    ts: dict[str, list[float]] = {k: [] for k in methods}
    maps: dict[str, ss.ShadowMap] = {}
    for _ in range(repeats):
        for label, method in methods.items():
            t = time.perf_counter()
            maps[label] = ss.soft_shadow_map(scene, light, resolution=res, extent=extent, method=method)
            ts[label].append(time.perf_counter() - t)
    return {k: (float(np.median(v)), maps[k]) for k, v in ts.items()}


def build(name: str) -> tuple[ss.Scene, ss.RectLight]:
    make = scenes.HARD_SURFACES.get(name) or scenes.SCENES[name]
    return make()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="+", default=[*STUDY, *scenes.HARD_SURFACES])
    p.add_argument("--reference-samples", type=int, default=1024)
    add_output_arguments(p, DOCS / "gaps.md")
    a = p.parse_args(argv)
    res = a.resolution

    report = Report("Gaps closed and open", command_line(__file__, argv))
    labels = list(SETTINGS)
    report.line("| scene | reference noise | " + " | ".join(labels) + " |")
    report.line("|---|---|" + "---|" * len(labels))
    signed_lines, time_lines, plan_lines = [], [], []
    worst: dict[str, float] = {k: 0.0 for k in labels}
    ratio: dict[str, float] = {k: 0.0 for k in labels}
    for name in a.scenes:
        scene, light = build(name)
        base = ss.soft_shadow_map(scene, light, resolution=res)
        occluders = list(scene.occluders)
        ref = cached_reference_map(name, base, occluders, samples=a.reference_samples, cache=CACHE)
        ref2 = cached_reference_map(name, base, occluders, samples=a.reference_samples, cache=CACHE, seed=1)
        noise = metrics.shadow_error(ref2, ref)
        mask = metrics.shadow_mask(ref)
        errs, signs, times = [], [], []
        measured: dict[str, tuple[float, float]] = {}

        methods = {k: m(res) if callable(m) else m for k, m in SETTINGS.items()}
        planned = {f"auto {target}": ss.Auto(error=target) for target in TARGETS}
        rounds = timed_rounds(scene, light, res, base.extent, a.repeats, {**methods, **planned})
        for label in SETTINGS:
            t, sm = rounds[label]
            e = metrics.shadow_error(sm.visibility, ref)
            measured[label] = (e, t)
            worst[label] = max(worst[label], e)
            errs.append(f"{e:.4f}")
            signs.append(f"{float(np.mean((sm.visibility - ref)[mask])):+.4f}")
            times.append(f"{t * 1e3:.0f}")
        probe = measured[labels[0]][1]
        if name in STUDY:
            for k in labels:
                ratio[k] = max(ratio[k], measured[k][1] / probe)
        for target in TARGETS:
            t, sm = rounds[f"auto {target}"]
            e = metrics.shadow_error(sm.visibility, ref)
            within = [(tt, k) for k, (ee, tt) in measured.items() if ee <= target]
            fastest = min(within) if within else None
            share = sm.timings["plan"] / sum(sm.timings.values())
            plan_lines.append(
                f"| {name} | {target} | {sm.method!r} | {e:.4f} | {'yes' if e <= target else '**no**'} "
                f"| {t * 1e3:.0f} | {sm.timings['plan'] * 1e3:.1f} ({share:.0%}) | "
                + (f"{fastest[1]} ({fastest[0] * 1e3:.0f} ms) | {t / fastest[0]:.2f} |" if fastest else "none | |")
            )
        report.line(f"| {name} | {noise:.4f} | " + " | ".join(errs) + " |")
        signed_lines.append(f"| {name} | " + " | ".join(signs) + " |")
        time_lines.append(f"| {name} | " + " | ".join(times) + " |")
    report.line("| **worst** | | " + " | ".join(f"**{worst[k]:.4f}**" for k in labels) + " |")
    report.line(
        "| **time / probe, largest on the study's scenes** | | " + " | ".join(f"{ratio[k]:.0f}" for k in labels) + " |"
    )
    report.line("")
    report.line("Mean signed error over the reference's shadow (> 0: too light):")
    report.line("")
    report.line("| scene | " + " | ".join(labels) + " |")
    report.line("|---|" + "---|" * len(labels))
    for line in signed_lines:
        report.line(line)
    report.line("")
    report.line(f"Time end to end from meshes (ms, medians of {runs(a.repeats)}; each round runs every setting once):")
    report.line("")
    report.line("| scene | " + " | ".join(labels) + " |")
    report.line("|---|" + "---|" * len(labels))
    for line in time_lines:
        report.line(line)
    report.line("")
    report.line(
        "`ss.Auto(error=target)` against the fastest fixed setting above whose error is within the target "
        "(time in ms; plan: the planning stage, ms and share of the planned run's stages; ratio = planned / "
        "fastest):"
    )
    report.line("")
    report.line("| scene | target | planned | error | met | time | plan | fastest fixed within | ratio |")
    report.line("|---|---|---|---|---|---|---|---|---|")
    for line in plan_lines:
        report.line(line)

    if not a.no_write:
        report.write(
            a.out,
            intro=(
                f"Light view at {res}², two occluder layers at the output's resolution. Errors are the paper's "
                "§4.2.1 metric (mean |V − V_ref| over the texels in umbra or penumbra) against "
                f"{a.reference_samples}-sample Mitsuba references; *reference noise* is the same metric between "
                "two such references with different seeds. *open*: the flat per-texel micro-patches; *closed* (the "
                "default): connected micro-quads ([bitmask](../methods/bitmask.md#gaps)). *auto rule*: "
                "`ss.Auto()`, the probe `ss.Auto(time=...)` times first; the planner's error bounds "
                "(`src/auto/plan.rs`) are this table's worst errors; its time ratios for `time=` were read "
                "from an earlier run's largest (they move between runs; constants above today's ratios only "
                "make budget plans more cautious). Scenes: "
                "`softshadow.scenes.SCENES` and `softshadow.scenes.HARD_SURFACES`."
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
