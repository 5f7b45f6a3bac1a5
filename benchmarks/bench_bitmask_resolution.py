"""How much of ``bitmask``'s error in the eye view is its occluder maps'
resolution: the same call with the maps at 1, 2 and 4 times the image's
resolution (each side), on the scenes of ``softshadow.scenes.as_built``.

    python benchmarks/bench_bitmask_resolution.py [--resolution 320 240] [--scenes ...] [--no-write]

Error over the pixels the reference shadows, acne and leaks as in
``bench_scenes.py`` (against the same cached 4096-sample Mitsuba
references); time is one run, wall clock, after the scene's first call.
Nothing is fitted here: the table says whether a finer map would bring the
method within a target, and at what cost. Writes
``docs/benchmarks/bitmask_resolution.md``.
"""

from __future__ import annotations

import argparse
import time

from _report import CACHE, DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference.cache import cached_reference_image
from softshadow.scenes.as_built import CALIBRATION, HELD_OUT, SCENES

FACTORS = (1, 2, 4)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--reference-samples", type=int, default=4096)
    p.add_argument("--scenes", nargs="*", default=list(SCENES))
    add_output_arguments(p, DOCS / "bitmask_resolution.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"bitmask against its occluder maps' resolution ({res[0]}×{res[1]})", command_line(__file__))
    head = " | ".join(f"maps {f}× (error, acne, leaks, ms)" for f in FACTORS)
    report.line(f"| scene | set | {head} |")
    report.line("|---|---|" + "---|" * len(FACTORS))
    worst = {(which, f): 0.0 for which in ("calibration", "held out") for f in FACTORS}
    for name in args.scenes:
        scene, light, cam = SCENES[name](res)
        which = "calibration" if name in CALIBRATION else "held out" if name in HELD_OUT else "?"
        ref = cached_reference_image(name, scene, light, cam, samples=args.reference_samples, cache=CACHE)
        ss.render(scene, light, cam, method=ss.Bitmask())  # warm-up
        cells = []
        for f in FACTORS:
            method = ss.Bitmask(occluder_resolution=(res[0] * f, res[1] * f))
            t = time.perf_counter()
            img = ss.render(scene, light, cam, method=method)
            ms = (time.perf_counter() - t) * 1e3
            c = compare_images(img, ref)
            worst[(which, f)] = max(worst.get((which, f), 0.0), c.shadow_error)
            cells.append(f"{c.shadow_error:.4f}, {c.acne:.2%}, {c.leak:.2%}, {ms:.0f}")
        report.line(f"| {name} | {which} | " + " | ".join(cells) + " |")
    report.line()
    report.line("| set | " + " | ".join(f"worst error, maps {f}×" for f in FACTORS) + " |")
    report.line("|---|" + "---|" * len(FACTORS))
    for which in ("calibration", "held out"):
        report.line(f"| {which} | " + " | ".join(f"{worst[(which, f)]:.4f}" for f in FACTORS) + " |")
    if not args.no_write:
        report.write(args.out)


if __name__ == "__main__":
    main()
