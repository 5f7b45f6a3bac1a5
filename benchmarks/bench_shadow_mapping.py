"""Scherzer 2005's experiments, and the widths of Chan & Durand 2003's
smoothies, measured.

    python benchmarks/bench_shadow_mapping.py [--resolution 640 480] [--repeats 3] [--no-write]

* Bias methods against acne and peter-panning: on every scene of
  ``softshadow.scenes.eye_view`` (2048² maps), each bias method of
  ``ss.ShadowMapping`` against the exact hard shadow (``exact`` with the
  light shrunk to its centre, or the sun to its direction): acne is the
  fraction of visible pixels lit there and shadowed by the map,
  peter-panning the fraction shadowed there and lit by the map.
* Uniform, focused and LiSPSM maps against resolution (512² to 4096²) on
  ``large_city`` (a large city seen from near the ground under the sun): the
  fraction of visible pixels misclassified against the exact hard shadow
  (aliasing error), and the time of the render (median of ``--repeats``).
* The eye-space blur's iterations against error and time, and Smoothies'
  width against error: against 256-sample ``exact`` under the scene's own
  (soft) light.

The measurements are ``softshadow.experiments.scherzer``'s (shared with the
study). Writes ``docs/benchmarks/shadow_mapping.md`` and the aliasing table into
``docs/methods/shadow_mapping.md`` between ``<!-- aliasing:start -->`` and
``<!-- aliasing:end -->``.
"""

from __future__ import annotations

import argparse

from _report import DOCS, ROOT, Report, add_output_arguments, command_line

from softshadow.experiments import scherzer
from softshadow.scenes.eye_view import EYE_SCENES

PAGE = ROOT / "docs" / "methods" / "shadow_mapping.md"
START, END = "<!-- aliasing:start -->", "<!-- aliasing:end -->"


def curve_rows(xs: tuple, curves: dict[str, list[tuple[float, float]]]) -> list[str]:
    return [
        f"| {x} | " + " | ".join(f"{c[i][0]:.4f} ({c[i][1] * 1000:.0f} ms)" for c in curves.values()) + " |"
        for i, x in enumerate(xs)
    ]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--repeats", type=int, default=3)
    add_output_arguments(p, DOCS / "shadow_mapping.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(
        f"Practical shadow mapping and smoothies ({res[0]}×{res[1]})", command_line(__file__), mitsuba=False
    )
    names = list(EYE_SCENES)

    report.line("## Bias methods: acne and peter-panning (2048² maps)")
    report.line("")
    report.line("| bias | " + " | ".join(f"{n}: acne / peter-panning" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    for label, per_scene in scherzer.bias_errors(res).items():
        cells = [f"{per_scene[n][0]:.4f} / {per_scene[n][1]:.4f}" for n in names]
        report.line(f"| {label} | " + " | ".join(cells) + " |")

    report.line("")
    report.line("## Aliasing: uniform, focused and LiSPSM maps in a large city")
    report.line("")
    rs = scherzer.RESOLUTIONS
    alias = ["| map | " + " | ".join(f"{r}²: misclassified (time)" for r in rs) + " |"]
    alias.append("|---|" + "---|" * len(rs))
    for label, curve in scherzer.aliasing_errors(res, args.repeats).items():
        alias.append(f"| {label} | " + " | ".join(f"{e:.4f} ({t * 1000:.0f} ms)" for e, t in curve) + " |")
    for line in alias:
        report.line(line)

    blur, width = scherzer.soft_curves(res, args.repeats)
    report.line("")
    report.line("## The eye-space blur: iterations against error and time (2048², soft light)")
    report.line("")
    report.line("| iterations | " + " | ".join(f"{n}: error (time)" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    for line in curve_rows(scherzer.BLUR_ITERATIONS, blur):
        report.line(line)

    report.line("")
    report.line("## Smoothies: width against error (soft light)")
    report.line("")
    report.line("| width | " + " | ".join(f"{n}: error (time)" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    for line in curve_rows(scherzer.SMOOTHIE_WIDTHS, width):
        report.line(line)

    if not args.no_write:
        report.write(
            args.out,
            intro=(
                "Hard-shadow errors are against the exact hard shadow (one ray per pixel to the light's "
                "centre or along the sun's direction); soft errors are mean |V - V_exact| against "
                "256-sample `exact` under the scene's own light. Times are medians of the repeats, "
                "end to end from the meshes."
            ),
        )
        page = PAGE.read_text()
        a, b = page.index(START) + len(START), page.index(END)
        body = f"\nFrom `{report.command}` ({report.date}):\n\n" + "\n".join(alias) + "\n"
        PAGE.write_text(page[:a] + body + page[b:])


if __name__ == "__main__":
    main()
