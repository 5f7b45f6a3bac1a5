"""What the extension's block cache (``src/block_cache.rs``) saves: the eye
view rendered with the cache and without it (``SOFTSHADOW_BLOCK_CACHE=off``),
each in a fresh process, page faults and time per render.

    python benchmarks/bench_alloc.py [--resolution 640 480] [--renders 30] [--rounds 3] [--no-write]

Each round runs both settings once per scene, in alternating order; the
table gives the medians over rounds of each process's mean per render (after
three warm-up renders): wall time, minor page faults and system CPU time
(``getrusage``). Writes ``docs/benchmarks/alloc.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

from softshadow.scenes.eye_view import EYE_SCENES

CHILD = r"""
import json, resource, sys, time
import softshadow as ss
from softshadow.scenes.eye_view import EYE_SCENES
name, w, h, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
scene, light, cam = EYE_SCENES[name]((w, h))
for _ in range(3):
    ss.render(scene, light, cam)
r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
for _ in range(n):
    ss.render(scene, light, cam)
t1, r1 = time.perf_counter(), resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"ms": (t1 - t0) / n * 1e3, "faults": (r1.ru_minflt - r0.ru_minflt) / n,
                  "sys_ms": (r1.ru_stime - r0.ru_stime) / n * 1e3}))
"""


def run(name: str, res: tuple[int, int], renders: int, cache: bool) -> dict[str, float]:
    env = dict(os.environ)
    env["SOFTSHADOW_BLOCK_CACHE"] = "on" if cache else "off"
    out = subprocess.run(
        [sys.executable, "-c", CHILD, name, str(res[0]), str(res[1]), str(renders)],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--renders", type=int, default=30)
    p.add_argument("--rounds", type=int, default=3)
    add_output_arguments(p, DOCS / "alloc.md")
    args = p.parse_args()
    res = (args.resolution[0], args.resolution[1])
    report = Report(f"The block cache in the eye view ({res[0]}×{res[1]}, method auto)", command_line(__file__))
    report.line("| scene | cache | time per render (ms) | page faults per render | system time per render (ms) |")
    report.line("|---|---|---|---|---|")
    for name in EYE_SCENES:
        rows: dict[bool, list[dict[str, float]]] = {True: [], False: []}
        for r in range(args.rounds):
            for cache in (True, False) if r % 2 == 0 else (False, True):
                rows[cache].append(run(name, res, args.renders, cache))
        for cache in (False, True):
            med = {k: float(np.median([x[k] for x in rows[cache]])) for k in ("ms", "faults", "sys_ms")}
            report.line(
                f"| {name} | {'on' if cache else 'off'} | {med['ms']:.1f} | {med['faults']:.0f} | {med['sys_ms']:.1f} |"
            )
    if not args.no_write:
        report.write(
            args.out,
            intro=(
                f"Medians over {args.rounds} rounds of each process's mean over {args.renders} renders "
                "(after 3 warm-up renders). `off` is the system allocator alone."
            ),
        )


if __name__ == "__main__":
    main()
