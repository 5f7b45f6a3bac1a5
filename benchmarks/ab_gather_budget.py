"""A/B of the gather kernels' work bounds (src/methods/gather/work.rs) on the
as-built scenes: run once with the shipped build and once with a build whose
PLANNED_VISITS and VISITS_PER_RECEIVER are f64::INFINITY (the rules off), then compare
the two JSON files: the occluder resolution each call ran with, its time,
and its error over the pixels the cached 4096-sample Mitsuba reference
shadows (``bench_scenes.py``'s cache).

    python benchmarks/ab_gather_budget.py out_rule.json      # the shipped build
    # set the two constants to f64::INFINITY, rebuild, then:
    python benchmarks/ab_gather_budget.py out_off.json
    python benchmarks/ab_gather_budget.py --compare out_off.json out_rule.json

How the thresholds were judged with it: docs/robustness.md.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from _report import ROOT

import softshadow as ss
from softshadow.metrics import shadow_error
from softshadow.reference.cache import cached_reference_image
from softshadow.scenes.as_built import HELD_OUT, SCENES


def measure(path: Path) -> None:
    out = {}
    for name, make in SCENES.items():
        scene, light, cam = make((640, 480))
        ref = cached_reference_image(name, scene, light, cam, samples=4096, cache=ROOT / ".cache" / "references")
        for method in ("ssm", "bitmask"):
            t = time.perf_counter()
            img = ss.render(scene, light, cam, method=method)
            seconds = time.perf_counter() - t
            out[f"{name}/{method}"] = dict(
                resolution=list(img.method.occluder_resolution),
                seconds=round(seconds, 2),
                error=round(shadow_error(img.visibility, ref.visibility), 4),
            )
            print(name, method, out[f"{name}/{method}"], flush=True)
    path.write_text(json.dumps(out, indent=1))


def compare(off: Path, on: Path) -> None:
    a, b = json.loads(off.read_text()), json.loads(on.read_text())
    changed = [k for k in a if a[k] != {**b[k], "seconds": a[k]["seconds"]}]
    print(f"{len(changed)} of {len(a)} calls differ")
    for k in changed:
        which = "held out" if k.split("/")[0] in HELD_OUT else "calibration"
        print(f"{k} ({which}): off {a[k]}  rule {b[k]}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", type=Path, nargs="+")
    p.add_argument("--compare", action="store_true", help="compare two JSON files: off, then rule")
    args = p.parse_args()
    if args.compare:
        compare(*args.out)
    else:
        measure(args.out[0])


if __name__ == "__main__":
    main()
