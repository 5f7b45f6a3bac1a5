"""The map methods' self-shadowing biases in the eye view: acne against leaks.

    python benchmarks/bench_bias.py [--resolution 320 240] [--method ssm] [--no-write]

On every scene of ``softshadow.scenes.eye_view`` (the bunny on its floor, the
self-shadowing torus, boxes and a sphere in contact under a large light, the
city under the sun), for each pair (normal_offset, depth_bias) of the grid
below, ``softshadow.render`` with the method is compared with a 1024-sample
``softshadow.reference.render_visibility`` on the pixels both see alike:

* error: the mean |V - V_ref|;
* acne: the fraction of the pixels the reference sees fully lit
  (V_ref = 1) that the method darkens below 0.98 (a surface shadowing
  itself through its own texels);
* leak: the mean of max(V - V_ref, 0) over the pixels the reference has at
  least half in shadow (V_ref <= 0.5): light let through where occluders
  meet or nearly meet receivers, which a larger bias causes.

Each cell is the worst of the four scenes. Writes ``docs/benchmarks/bias.md``.
"""

from __future__ import annotations

import argparse

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.metrics import compare_images
from softshadow.reference import render_visibility
from softshadow.scenes.eye_view import EYE_SCENES

NORMAL_OFFSETS = (0.0, 0.25, 0.5, 1.0, 2.0)
DEPTH_BIASES = (0.0, 0.5, 1.0, 2.0)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--method", default="ssm", choices=["ssm", "bitmask"])
    add_output_arguments(p, DOCS / "bias.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(
        f"Self-shadowing biases of {args.method} in the eye view ({res[0]}×{res[1]})", command_line(__file__)
    )
    cases = []
    for name, make in EYE_SCENES.items():
        scene, light, cam = make(res)
        cases.append((name, scene, light, cam, render_visibility(scene, light, cam, samples=1024)))
    report.line(
        "| normal_offset (texels) | depth_bias (texels) | error (worst scene) | acne (worst) | leak (worst) | "
        "error per scene |"
    )
    report.line("|---|---|---|---|---|---|")
    for no in NORMAL_OFFSETS:
        for db in DEPTH_BIASES:
            errors, acne, leak = [], [], []
            for _, scene, light, cam, ref in cases:
                img = ss.render(scene, light, cam, method=args.method, normal_offset=no, depth_bias=db)
                c = compare_images(img, ref)
                m = c.mask
                lit = m & (ref.visibility == 1.0)
                dark = m & (ref.visibility <= 0.5)
                d = img.visibility - ref.visibility
                errors.append(c.mean_abs)
                acne.append(float((img.visibility[lit] < 0.98).mean()) if lit.any() else 0.0)
                leak.append(float(np.maximum(d[dark], 0).mean()) if dark.any() else 0.0)
            default = " (default)" if (no, db) == (0.25, 0.5) else ""
            per = ", ".join(f"{n} {e:.4f}" for (n, *_), e in zip(cases, errors, strict=True))
            report.line(f"| {no}{default} | {db} | {max(errors):.4f} | {max(acne):.4f} | {max(leak):.4f} | {per} |")
    if not args.no_write:
        report.write(
            args.out,
            intro=(
                "Without bias up to 55% of the lit pixels shadow themselves (acne, worst scene); a quarter "
                "texel of normal offset with half a texel of depth bias brings that to 0.3% (what is "
                "left are the maps' penumbra edges), and every further texel of either bias lets more "
                "light through in the shadows (leak). The defaults are the row marked (default)."
            ),
        )


if __name__ == "__main__":
    main()
