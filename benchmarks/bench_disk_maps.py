"""The map methods under a disk light against Mitsuba, beside the same
methods under the rectangle the disk replaces.

    python benchmarks/bench_disk_maps.py [--resolution 160 120] [--mitsuba-samples 1024]
        [--scenes ...] [--no-write]

For each as-built scene lit by a rectangle (``softshadow.scenes.as_built``;
the sun's scenes have no disk to compare), the rectangle and the disk of its
area at its centre: the error over the pixels the reference shadows
(``softshadow.metrics.compare_images``: mean |V − V_ref| where 1 − V_ref
exceeds its threshold, with acne and leaks beside it), against
``softshadow.reference.render_visibility`` at ``--mitsuba-samples`` a pixel
(seed 0); the noise column is seed 1 against it. Methods at their defaults:
``pcss`` (its boxes the ellipses inscribed in them under a disk),
``smoothies`` (its width the disk's diameter), ``ssm`` and ``bitmask``
(1024 samples). "smoothies, segment" is the smoothies' visibility v passed
through the profile of a straight edge across a disk, the circular
segment's area (acos(1 − 2v) − (1 − 2v) √(1 − (1 − 2v)²)) / π, instead of
its linear ramp: the choice the method does not make (docs/methods/
smoothies.md). The set column says which scenes the choice was made on
(calibration) and which judged it (held out). Prints the table and writes
it to ``docs/benchmarks/disk_maps.md``.
"""

from __future__ import annotations

import argparse
import dataclasses
from typing import Any

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference import render_visibility
from softshadow.scenes import as_built

METHODS: list[tuple[str, Any]] = [
    ("pcss", ss.PCSS()),
    ("smoothies", ss.Smoothies()),
    ("ssm", ss.Ssm()),
    ("bitmask 1024", ss.Bitmask(samples=1024)),
]


def segment(v: np.ndarray) -> np.ndarray:
    """The visible fraction of a disk whose edge-on occluder has swept
    1 − v of its diameter: a circular segment's area over the disk's."""
    c = 1.0 - 2.0 * np.clip(v, 0.0, 1.0)
    return (np.arccos(c) - c * np.sqrt(np.maximum(1.0 - c * c, 0.0))) / np.pi


def cell(image: Any, reference: Any) -> str:
    c = compare_images(image, reference)
    return f"{c.shadow_error:.4f} ({100 * c.acne:.2f}%, {100 * c.leak:.2f}%)"


def rows(report: Report, name: str, group: str, scene: Any, light: Any, cam: Any, samples: int) -> None:
    sx, sy = light.size
    r = float(np.sqrt(sx * sy / np.pi))
    disk = ss.DiskLight(light.center, light.normal, r)
    for kind, lt in ((f"rectangle {sx:g}×{sy:g}", light), (f"disk r {r:.3g}", disk)):
        reference = render_visibility(scene, lt, cam, samples=samples, seed=0)
        noise = compare_images(render_visibility(scene, lt, cam, samples=samples, seed=1), reference)
        cells = {}
        for label, method in METHODS:
            img = ss.render(scene, lt, cam, method=method)
            cells[label] = cell(img, reference)
            if label == "smoothies":
                shaped = dataclasses.replace(img, visibility=segment(img.visibility))
                cells["smoothies, segment"] = cell(shaped, reference)
        order = ["pcss", "smoothies", "smoothies, segment", "ssm", "bitmask 1024"]
        report.line(
            f"| {name} | {group} | {kind} | {noise.shadow_error:.4f} | " + " | ".join(cells[k] for k in order) + " |"
        )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(160, 120), metavar=("W", "H"))
    p.add_argument("--mitsuba-samples", type=int, default=1024)
    p.add_argument("--scenes", nargs="*", default=list(as_built.SCENES))
    add_output_arguments(p, DOCS / "disk_maps.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"Map methods under disks against Mitsuba ({res[0]}×{res[1]})", command_line(__file__))
    report.line("| scene | set | light | Mitsuba noise | pcss | smoothies | smoothies, segment | ssm | bitmask 1024 |")
    report.line("|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        scene, light, cam = as_built.SCENES[name](res)
        if not isinstance(light, ss.RectLight):
            continue
        group = "calibration" if name in as_built.CALIBRATION else "held out"
        rows(report, name, group, scene, light, cam, args.mitsuba_samples)
    if args.no_write:
        return
    intro = (
        f"Each cell: the error over the pixels the reference shadows, mean |V − V_ref| "
        f"(`compare_images`' `shadow_error`), then acne and leaks (the fractions of the matched pixels "
        f"lit in the reference and darker by more than 0.05, and in its umbra and lighter by more than 0.05), "
        f"against `render_visibility` at {args.mitsuba_samples} samples a pixel (seed 0); the noise column is "
        "seed 1 against it. Every method at its defaults (`bitmask` with 1024 samples). The disk has the "
        "rectangle's area, at its centre. `smoothies, segment` passes the smoothies' visibility through a "
        "disk's edge profile (the circular segment) instead of their linear ramp; the smoothies keep the "
        "ramp, chosen on the calibration scenes and judged on the held-out ones."
    )
    report.write(args.out, intro=intro)


if __name__ == "__main__":
    main()
