"""The eye view's `Auto(error=e)` against the run its law alone would make:
what the 16-sample pilot, its refinements and the shared first hits, framing
and BVH cost or save, scene by scene (docs/methods/auto.md).

    python benchmarks/bench_auto_pilot.py [--resolution 320 240] [--repeats 3] [--targets 0.01 0.005]

For each scene of ``softshadow.scenes.as_built`` (calibration, then held
out): ``ss.render(..., method=ss.Auto(error=e))`` and, interleaved in the
same rounds, ``Exact(samples=n)`` with its fixed-draw estimate, n the count
the plan's law asks for (its ``setting`` decision). Medians of
``--repeats`` rounds; prints a table (error over shadowed pixels against
the cached 4096-sample Mitsuba references of ``bench_scenes.py``).
"""

from __future__ import annotations

import argparse
import re
import statistics
import time
from pathlib import Path
from typing import Any

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference.cache import cached_reference_image
from softshadow.scenes.as_built import CALIBRATION, HELD_OUT

CACHE = Path(__file__).resolve().parent.parent / ".cache" / "references"


def timed(*args: Any, **kw: Any) -> tuple[float, Any]:
    """`ss.render(*args, **kw)` and its seconds."""
    t = time.perf_counter()
    out = ss.render(*args, **kw)
    return time.perf_counter() - t, out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--targets", type=float, nargs="*", default=[0.01, 0.005])
    p.add_argument("--reference-samples", type=int, default=4096)
    args = p.parse_args()
    res = tuple(args.resolution)
    print(
        "| scene | set | target | Auto ran | Auto (ms) | its error | the law's exact | its time (ms) "
        "| its error | Auto / law |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for which, scenes in (("calibration", CALIBRATION), ("held out", HELD_OUT)):
        for name, make in scenes.items():
            scene, light, cam = make(res)
            ref = cached_reference_image(name, scene, light, cam, samples=args.reference_samples, cache=CACHE)
            for e in args.targets:
                plan = ss.render(scene, light, cam, method=ss.Auto(error=e)).plan
                law = int(re.search(r"exact with (\d+) samples", plan.decisions[0].why).group(1))
                ta: list[float] = []
                tl: list[float] = []
                for _ in range(args.repeats):
                    t, auto = timed(scene, light, cam, method=ss.Auto(error=e))
                    ta.append(t)
                    t, alone = timed(scene, light, cam, method=ss.Exact(samples=law), estimate_error="fixed")
                    tl.append(t)
                a, b = statistics.median(ta), statistics.median(tl)
                print(
                    f"| {name} | {which} | {e} | {auto.method!r} | {a * 1e3:.0f} "
                    f"| {compare_images(auto, ref).shadow_error:.4f} | Exact(samples={law}) | {b * 1e3:.0f} "
                    f"| {compare_images(alone, ref).shadow_error:.4f} | {a / b:.2f} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
