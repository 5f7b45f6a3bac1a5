"""The README's table: every method's error and time against Mitsuba, on one scene.

    python benchmarks/methods_table.py [--repeats 5] [--no-write]

On the bunny floating over the floor (``softshadow.scenes.bunny_floating()``,
256² maps), for each call in ``CALLS``: the median wall time end to end from
meshes over ``--repeats`` runs (after one warm-up) and the error against a
1024-sample Mitsuba reference (the paper's §4.2.1 metric: the mean |V - V_ref|
over the texels the reference has in umbra or penumbra). Then Mitsuba's own
``ray_test`` time (rays already in Dr.Jit arrays) at 4 to 512 samples per
texel (medians of ``--repeats`` runs after a warm-up), and, for each call, Mitsuba's time to reach that call's error,
interpolated log-log between those sample counts (the study's
``mitsuba_seconds_at``; * where it extrapolates).

Prints the markdown table, writes it to ``docs/benchmarks/methods.md`` with a
header naming the command, the machine and the date, and rewrites the README's
table between ``<!-- methods-table:start -->`` and ``<!-- methods-table:end -->``
(``--no-write``: print only). The reference is cached in ``.cache/references/``
like the tests' (delete it to recompute).
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import os
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")

import softshadow as ss  # noqa: E402
from softshadow import metrics, reference, scenes  # noqa: E402


@dataclass
class Point:
    """One measured setting, as the study's ``Point``: what ``mitsuba_seconds_at`` reads."""

    scene: str
    method: str
    setting: str
    seconds: float
    error: float


def _local_mitsuba_seconds_at(error: float, points: list[Point]) -> tuple[float, bool]:
    """The study's ``mitsuba_seconds_at``, for when the study cannot be imported:
    Mitsuba's time at ``error``, log-log between its sample counts (the last
    segment's slope beyond them), and whether that extrapolates."""
    mi = sorted((p.error, p.seconds) for p in points if p.method == "mitsuba")
    le, lt = np.log([m[0] for m in mi]), np.log([m[1] for m in mi])
    x = np.log(error)
    outside = not (le[0] <= x <= le[-1])
    i = 0 if x < le[0] else max(0, min(len(le) - 2, int(np.searchsorted(le, x)) - 1))
    slope = (lt[i + 1] - lt[i]) / (le[i + 1] - le[i])
    return float(np.exp(lt[i] + slope * (x - le[i]))), outside


try:  # the study's own interpolation (softshadow.experiments.study in 0.2, softshadow.study before)
    from softshadow.experiments.study import mitsuba_seconds_at  # noqa: E402
except ImportError:
    try:
        from softshadow.study import mitsuba_seconds_at  # noqa: E402
    except ImportError as e:
        print(f"the study does not import ({e}); using this script's copy of mitsuba_seconds_at", file=sys.stderr)
        mitsuba_seconds_at = _local_mitsuba_seconds_at

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


def _key(*parts: object) -> str:
    """The cache key of tests/conftest.py, so the tests and this script share references."""
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(np.ascontiguousarray(p).tobytes())
        else:
            h.update(repr(p).encode())
    return h.hexdigest()[:24]


def reference_map(sm: ss.ShadowMap, occluders: list, samples: int) -> np.ndarray:
    key = _key(SCENE, sm.light, sm.extent, sm.receiver_depth, samples, [m[0] for m in occluders])
    path = CACHE / f"{SCENE}-{key}.npy"
    if path.exists():
        return np.load(path)
    ref = reference.reference_map(sm, occluders, samples=samples)
    CACHE.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npy")
    np.save(tmp, ref)
    tmp.replace(path)
    return ref


def median_seconds(fn, repeats: int) -> float:
    fn()  # warm-up
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def _setting(sm: ss.ShadowMap, name: str) -> object:
    """A resolved setting of a result: from its typed config (0.2) or its attributes (0.1)."""
    config = sm.method
    if not isinstance(config, str) and hasattr(config, name):
        return getattr(config, name)
    return getattr(sm, name, None)


def what_ran(sm: ss.ShadowMap) -> str:
    """A short description of the method and settings a result was computed with."""
    config = sm.method
    name = config if isinstance(config, str) else type(config).__name__.lower()
    parts = [name]
    if sm.occluder_depth is not None:
        passes = _setting(sm, "passes")
        parts.append(f"{passes} pass{'es' if passes != 1 else ''}")
        h, w = sm.occluder_depth.shape
        parts.append(f"occluders {w}²" if w == h else f"occluders {w}×{h}")
    samples = _setting(sm, "samples")
    if samples:
        parts.append(f"{samples} samples")
    hierarchy = _setting(sm, "hierarchy")
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
    scene, light = scenes.bunny_floating()
    occluders = list(scene.occluders)
    base = ss.soft_shadow_map(scene, light, resolution=RESOLUTION)
    ref = reference_map(base, occluders, REFERENCE_SAMPLES)

    rows = []
    for label, kwargs in CALLS:

        def run(kwargs=kwargs) -> ss.ShadowMap:
            return ss.soft_shadow_map(scene, light, resolution=RESOLUTION, **kwargs)

        seconds = median_seconds(run, repeats)
        sm = run()
        if tuple(sm.extent) != tuple(base.extent):
            raise SystemExit(f"{label}: fitted extent {sm.extent} differs from the reference's {base.extent}")
        error = metrics.shadow_error(sm.visibility, ref)
        rows.append((label, what_ran(sm), Point(SCENE, "softshadow", label, seconds, error)))
        print(f"  {label}: {seconds * 1e3:.1f} ms, error {error:.4f}", file=sys.stderr)

    rscene = reference.ReferenceScene(occluders)
    mitsuba = []
    for k in MITSUBA_SAMPLES:
        reference.reference_map(base, rscene, samples=k, seed=repeats)  # warm-up at this size
        times, error = [], 0.0
        for seed in range(repeats):
            v = reference.reference_map(base, rscene, samples=k, seed=seed)
            times.append(rscene.last_stats.trace_seconds)
            error = metrics.shadow_error(v, ref)
        mitsuba.append((k, Point(SCENE, "mitsuba", f"{k} samples", float(np.median(times)), error)))
        print(f"  Mitsuba {k} samples: {np.median(times) * 1e3:.1f} ms, error {error:.4f}", file=sys.stderr)
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
    text = README.read_text()
    if START not in text or END not in text:
        print(f"README.md has no {START} ... {END} markers: left as it is", file=sys.stderr)
        return False
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    README.write_text(f"{head}{START}\n{table}\n{END}{tail}")
    return True


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
        f"{RESOLUTION}² maps. Times are medians of {a.repeats} runs end to end from meshes "
        "(all cores); Mitsuba's are `ray_test` alone, with the rays already in Dr.Jit arrays. "
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
