"""Scherzer 2005's experiments, and the widths of Chan & Durand 2003's
smoothies, measured.

    python benchmarks/bench_shadow_mapping.py [--resolution 640 480] [--repeats 3] [--no-write]

* Bias methods against acne and peter-panning: on every scene of
  ``softshadow.eye_scenes`` (2048² maps), each bias method of
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

Writes ``docs/benchmarks/shadow_mapping.md`` and the aliasing table into
``docs/methods/shadow_mapping.md`` between ``<!-- aliasing:start -->`` and
``<!-- aliasing:end -->``.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
from _report import DOCS, ROOT, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.eye_scenes import EYE_SCENES, large_city

PAGE = ROOT / "docs" / "methods" / "shadow_mapping.md"
START, END = "<!-- aliasing:start -->", "<!-- aliasing:end -->"
BIASES: list[tuple[str, Any]] = [
    ("none (ConstantBias(constant=0))", ss.ConstantBias(constant=0)),
    ("ConstantBias(constant=1000)", ss.ConstantBias(constant=1000)),
    ("SlopeScaleBias() (default)", ss.SlopeScaleBias()),
    ("LinearDepthBias()", ss.LinearDepthBias()),
    ("BackFaces()", ss.BackFaces()),
    ("MidpointBias()", ss.MidpointBias()),
]
MAPS: list[tuple[str, dict[str, Any]]] = [
    ("unfocused", dict(focus=False)),
    ("focused", dict(focus=True)),
    ("focused LiSPSM (middle vector)", dict(warp=ss.LiSPSM())),
    ("focused LiSPSM (camera axis)", dict(warp=ss.LiSPSM(vector="camera"))),
]
RESOLUTIONS = (512, 1024, 2048, 4096)


def hard(light: Any) -> Any:
    if isinstance(light, ss.RectLight):
        return ss.RectLight(light.center, light.normal, light.up, size=(0.0, 0.0))
    return ss.DirectionalLight(light.direction, light.up, angular_size=(0.0, 0.0))


def timed(fn: Any, repeats: int) -> tuple[float, Any]:
    out, times = None, []
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


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

    report.line("## Bias methods: acne and peter-panning (2048² maps)")
    report.line("")
    names = list(EYE_SCENES)
    report.line("| bias | " + " | ".join(f"{n}: acne / peter-panning" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    cases = []
    for name in names:
        scene, light, cam = EYE_SCENES[name](res)
        h = hard(light)
        cases.append((scene, light, h, cam, ss.render(scene, h, cam, method="exact")))
    for label, bias in BIASES:
        cells = []
        for scene, _, h, cam, ref in cases:
            img = ss.render(scene, h, cam, method=ss.ShadowMapping(bias=bias))
            r, v, m = ref.visibility > 0.5, img.visibility > 0.5, ref.mask
            cells.append(f"{np.mean((r & ~v)[m]):.4f} / {np.mean((~r & v)[m]):.4f}")
        report.line(f"| {label} | " + " | ".join(cells) + " |")

    report.line("")
    report.line("## Aliasing: uniform, focused and LiSPSM maps in a large city")
    report.line("")
    scene, sun, cam = large_city(res)
    h = hard(sun)
    ref = ss.render(scene, h, cam, method="exact")
    alias = ["| map | " + " | ".join(f"{r}²: misclassified (time)" for r in RESOLUTIONS) + " |"]
    alias.append("|---|" + "---|" * len(RESOLUTIONS))
    for label, kw in MAPS:
        cells = []
        for r in RESOLUTIONS:
            sec, img = timed(
                lambda kw=kw, r=r: ss.render(scene, h, cam, method=ss.ShadowMapping(resolution=r, **kw)), args.repeats
            )
            wrong = np.mean(((img.visibility > 0.5) != (ref.visibility > 0.5))[ref.mask])
            cells.append(f"{wrong:.4f} ({sec * 1000:.0f} ms)")
        alias.append(f"| {label} | " + " | ".join(cells) + " |")
    for line in alias:
        report.line(line)

    report.line("")
    report.line("## The eye-space blur: iterations against error and time (2048², soft light)")
    report.line("")
    report.line("| iterations | " + " | ".join(f"{n}: error (time)" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    soft = [(s, li, c, ss.render(s, li, c, method=ss.Exact(samples=256))) for s, li, _, c, _ in cases]
    for it in (0, 1, 2, 4, 8, 16):
        cells = []
        for s, li, c, r in soft:
            blur = ss.EyeSpaceBlur(iterations=it) if it else None
            sec, img = timed(
                lambda s=s, li=li, c=c, b=blur: ss.render(s, li, c, method=ss.ShadowMapping(blur=b)), args.repeats
            )
            err = np.abs(img.visibility - r.visibility)[r.mask].mean()
            cells.append(f"{err:.4f} ({sec * 1000:.0f} ms)")
        report.line(f"| {it} | " + " | ".join(cells) + " |")

    report.line("")
    report.line("## Smoothies: width against error (soft light)")
    report.line("")
    report.line("| width | " + " | ".join(f"{n}: error (time)" for n in names) + " |")
    report.line("|---|" + "---|" * len(names))
    for w in (0.25, 0.5, 1.0, 2.0, 4.0):
        cells = []
        for s, li, c, r in soft:
            sec, img = timed(
                lambda s=s, li=li, c=c, w=w: ss.render(s, li, c, method=ss.Smoothies(width=w)), args.repeats
            )
            err = np.abs(img.visibility - r.visibility)[r.mask].mean()
            cells.append(f"{err:.4f} ({sec * 1000:.0f} ms)")
        report.line(f"| {w} | " + " | ".join(cells) + " |")

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
