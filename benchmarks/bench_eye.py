"""The eye view against Mitsuba: every method's time and error on the eye-view
scenes, and Mitsuba's time at equal error.

    python benchmarks/bench_eye.py [--resolution 640 480] [--repeats 7] [--scenes ...] [--no-write]

For each scene of ``softshadow.scenes.eye_view.EYE_SCENES`` at the resolution,
the measurement of ``softshadow.experiments.eye_plane`` (shared with the
study): the reference (``--reference-samples`` stratified light samples a
pixel), Mitsuba's whole eye-view job at 1 to 256 samples
(``softshadow.reference.eye_job``), and every call of
``eye_plane.CALLS`` end to end from the meshes, with Mitsuba's time at
its error († where one sample a pixel already does as well, * where it
extrapolates). Medians of ``--repeats`` rounds in one run. Prints the tables, writes them to
``docs/benchmarks/eye.md`` and one row per scene (the fastest call within
``BAR_ERROR`` and its ratio to Mitsuba at that error) into the README
between ``<!-- eye-table:start -->`` and ``<!-- eye-table:end -->``.
"""

from __future__ import annotations

import argparse

from _report import DOCS, ROOT, Report, add_output_arguments, command_line, replace_block, runs

from softshadow.experiments.eye_plane import best_within, eye_plane, markdown_eye_plane
from softshadow.scenes.eye_view import EYE_SCENES

README = ROOT / "README.md"
START, END = "<!-- eye-table:start -->", "<!-- eye-table:end -->"
BAR_ERROR = 0.02


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--reference-samples", type=int, default=4096)
    p.add_argument("--scenes", nargs="*", default=list(EYE_SCENES))
    add_output_arguments(p, DOCS / "eye.md")
    args = p.parse_args()
    res = tuple(args.resolution)
    report = Report(f"Eye view against Mitsuba ({res[0]}×{res[1]})", command_line(__file__))
    summary: list[str] = []
    for name in args.scenes:
        plane = eye_plane(name, res, repeats=args.repeats, reference_samples=args.reference_samples)
        report.line(f"## {name}")
        report.line()
        report.line(
            f"{plane.light}; {plane.coverage:.0%} of the pixels see a surface; reference "
            f"{plane.reference_samples} samples."
        )
        report.line()
        for line in markdown_eye_plane(plane):
            report.line(line)
        report.line()
        best = best_within(plane, BAR_ERROR)
        if best is not None:
            summary.append(
                f"| {name} | {best.label} | {best.seconds * 1e3:.0f} | {best.error:.4f} | "
                f"{best.mitsuba_seconds * 1e3:.0f}{best.mark} | {best.mitsuba_seconds / best.seconds:.1f}{best.mark} |"
            )
        else:
            summary.append(f"| {name} | none within {BAR_ERROR} | | | | |")
    table = [
        f"| scene ({res[0]}×{res[1]}) | fastest call with error over shadowed pixels ≤ {BAR_ERROR} "
        "| time (ms) | error | "
        "Mitsuba at equal error (ms) | speed-up |",
        "|---|---|---|---|---|---|",
        *summary,
    ]
    report.line("## Summary")
    report.line()
    for line in table:
        report.line(line)
    if args.no_write:
        return
    intro = (
        f"Times are medians of {runs(args.repeats)} after a warm-up. Mitsuba's time at equal "
        "error is interpolated log-log between its sample counts; † where its fewest samples "
        "(one a pixel) already reach that error, so its time is theirs; * where it extrapolates "
        "beyond its most samples."
    )
    report.write(args.out, intro=intro)
    replace_block(README, START, END, table)


if __name__ == "__main__":
    main()
