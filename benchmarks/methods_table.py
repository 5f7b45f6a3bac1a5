"""The README's table: every method's error and time against Mitsuba, on one scene.

    python benchmarks/methods_table.py [--repeats 5] [--no-write]

On the bunny floating over the floor (``softshadow.scenes.bunny_floating()``,
256² maps), for each call in ``CALLS``: the wall time end to end from meshes
and the error against a 1024-sample Mitsuba reference (the paper's §4.2.1
metric: the mean |V - V_ref| over the texels the reference has in umbra or
penumbra); Mitsuba's own ``ray_test`` time (rays already in Dr.Jit arrays) and
error at 4 to 512 samples per texel; and, for each call, Mitsuba's time to
reach that call's error, interpolated log-log between those sample counts (the
study's ``mitsuba_seconds_at``; * where it extrapolates). Times are medians of
``--repeats`` rounds after a warm-up round; each round times every call and
every sample count once, so that on a shared machine both sides of a ratio
see the same load.

Prints the markdown table, writes it to ``docs/benchmarks/methods.md`` with a
header naming the command, the machine and the date, and rewrites the README's
table between ``<!-- methods-table:start -->`` and ``<!-- methods-table:end -->``
(``--no-write``: print only). The reference is cached in ``.cache/references/``
like the tests' (delete it to recompute).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
from _report import replace_block

import softshadow as ss
from softshadow import metrics, reference, scenes
from softshadow.experiments.points import Point, mitsuba_seconds_at
from softshadow.reference.cache import cached_reference_map

ROOT = Path(__file__).resolve().parent.parent
CACHE = ROOT / ".cache" / "references"
TABLE = ROOT / "docs" / "benchmarks" / "methods.md"
README = ROOT / "README.md"
START, END = "<!-- methods-table:start -->", "<!-- methods-table:end -->"
COMMAND = "python benchmarks/methods_table.py"

SCENE = "bunny_floating"
RESOLUTION = 256
REFERENCE_SAMPLES = 1024
MITSUBA_SAMPLES = (4, 16, 64, 256, 512)
# (what the README calls it, the keyword arguments of soft_shadow_map)
CALLS: list[tuple[str, dict[str, object]]] = [
    ('`method="ssm"` (defaults: as published)', {"method": "ssm"}),
    ('`method="ssm", occluder_resolution=64`', {"method": "ssm", "occluder_resolution": 64}),
    ('`method="auto"`', {"method": "auto"}),
    ('`method="bitmask", samples=64`', {"method": "bitmask", "samples": 64}),
    ('`method="bitmask", samples=256`', {"method": "bitmask", "samples": 256}),
    ('`method="exact", samples=256`', {"method": "exact", "samples": 256}),
]


def what_ran(sm: ss.ShadowMap) -> str:
    """A short description of the method and settings a result was computed with."""
    config = sm.method
    parts = [config.name]
    if sm.occluder_depth is not None:
        passes = sm.passes
        parts.append(f"{passes} pass{'es' if passes != 1 else ''}")
        h, w = sm.occluder_depth.shape
        parts.append(f"occluders {w}²" if w == h else f"occluders {w}×{h}")
    samples = getattr(config, "samples", None)
    if samples:
        parts.append(f"{samples} samples")
    hierarchy = getattr(config, "hierarchy", None)
    if hierarchy is not None:
        parts.append("hierarchy" if hierarchy else "no hierarchy")
    return ", ".join(parts)


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def measure(repeats: int) -> tuple[list[tuple[str, str, Point]], list[tuple[int, Point]]]:
    """Times every call and every Mitsuba sample count once per round, for
    ``repeats`` rounds after a warm-up round, and takes the medians: on a
    machine shared with other jobs, both sides of a ratio see the same load."""
    scene, light = scenes.bunny_floating()
    occluders = list(scene.occluders)
    base = ss.soft_shadow_map(scene, light, resolution=RESOLUTION)
    ref = cached_reference_map(SCENE, base, occluders, samples=REFERENCE_SAMPLES, cache=CACHE)
    rscene = reference.ReferenceScene(occluders)

    def run(kwargs: dict[str, object]) -> ss.ShadowMap:
        return ss.soft_shadow_map(scene, light, resolution=RESOLUTION, **kwargs)

    def trace(k: int, seed: int) -> tuple[np.ndarray, float]:
        v = reference.reference_map(base, rscene, samples=k, seed=seed)
        return v, rscene.last_stats.trace_seconds

    results = {label: run(kwargs) for label, kwargs in CALLS}  # warm-up round
    mitsuba_maps = {k: trace(k, repeats)[0] for k in MITSUBA_SAMPLES}
    times: dict[object, list[float]] = {key: [] for key in [*results, *MITSUBA_SAMPLES]}
    for seed in range(repeats):
        for label, kwargs in CALLS:
            t = time.perf_counter()
            run(kwargs)
            times[label].append(time.perf_counter() - t)
        for k in MITSUBA_SAMPLES:
            mitsuba_maps[k], seconds = trace(k, seed)
            times[k].append(seconds)

    rows = []
    for label, _ in CALLS:
        sm = results[label]
        if tuple(sm.extent) != tuple(base.extent):
            raise SystemExit(f"{label}: fitted extent {sm.extent} differs from the reference's {base.extent}")
        seconds, error = float(np.median(times[label])), metrics.shadow_error(sm.visibility, ref)
        rows.append((label, what_ran(sm), Point(SCENE, "softshadow", label, seconds, error)))
        print(f"  {label}: {seconds * 1e3:.1f} ms, error {error:.4f}", file=sys.stderr)
    mitsuba = []
    for k in MITSUBA_SAMPLES:
        seconds, error = float(np.median(times[k])), metrics.shadow_error(mitsuba_maps[k], ref)
        mitsuba.append((k, Point(SCENE, "mitsuba", f"{k} samples", seconds, error)))
        print(f"  Mitsuba {k} samples: {seconds * 1e3:.1f} ms, error {error:.4f}", file=sys.stderr)
    return rows, mitsuba


def markdown(rows: list[tuple[str, str, Point]], mitsuba: list[tuple[int, Point]]) -> str:
    points = [m for _, m in mitsuba]
    lines = [
        "| call | what ran | time (ms) | error | Mitsuba at equal error (ms) | Mitsuba time / time |",
        "|---|---|---|---|---|---|",
    ]
    for label, ran, p in rows:
        t, outside = mitsuba_seconds_at(p.error, points)
        mark = "*" if outside else ""
        lines.append(
            f"| {label} | {ran} | {p.seconds * 1e3:.1f} | {p.error:.4f} "
            f"| {t * 1e3:.1f}{mark} | {t / p.seconds:.2f}{mark} |"
        )
    for k, p in mitsuba:
        lines.append(f"| Mitsuba `ray_test`, {k} samples | | {p.seconds * 1e3:.1f} | {p.error:.4f} | | |")
    return "\n".join(lines)


def rewrite_readme(table: str) -> bool:
    return replace_block(README, START, END, [table])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeats", type=int, default=5, help="timed runs per call (median)")
    p.add_argument("--no-write", action="store_true", help="print the table only")
    a = p.parse_args(argv)
    if a.repeats < 1:
        p.error("--repeats: must be >= 1")

    started = time.perf_counter()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    rows, mitsuba = measure(a.repeats)
    table = markdown(rows, mitsuba)
    command = COMMAND + (f" --repeats {a.repeats}" if a.repeats != 5 else "")
    today = datetime.date.today().isoformat()
    machine = f"{cpu_name()}, {os.cpu_count()} cores (load average {load:.2f} when it started)"
    print(table)
    print(f"({time.perf_counter() - started:.0f} s)", file=sys.stderr)
    if a.no_write:
        return 0

    TABLE.parent.mkdir(parents=True, exist_ok=True)
    TABLE.write_text(
        "# Methods against Mitsuba: the README's table\n\n"
        f"Generated by `{command}` on {today}: {machine}; softshadow {ss.__version__}, "
        f"Mitsuba {reference.variant()}.\n\n"
        f"Scene: the bunny floating over the floor (`softshadow.scenes.bunny_floating()`), "
        f"{RESOLUTION}² maps. Times are medians of {a.repeats} rounds after a warm-up round, each round "
        "timing every call and every Mitsuba sample count once (so both sides of a ratio see the same load): "
        "softshadow's end to end from meshes on all cores, Mitsuba's `ray_test` alone, with the rays "
        "already in Dr.Jit arrays. "
        f"Errors are the paper's §4.2.1 metric (mean |V − V_ref| over the texels in umbra or penumbra) "
        f"against a {REFERENCE_SAMPLES}-sample Mitsuba reference. Mitsuba's time at a call's error is "
        "interpolated log-log between its sample counts (* where it extrapolates).\n\n"
        f"{table}\n"
    )
    readme = rewrite_readme(table)
    print(f"wrote {TABLE.relative_to(ROOT)}" + (" and README.md" if readme else ""), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
