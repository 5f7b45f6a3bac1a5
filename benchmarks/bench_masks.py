"""`exact`'s two engines on the same samples: the rays (one shadow ray a
light sample) against the masks (each pixel's samples marked by the
triangles crossing its light), and the default call beside them (its
probe, then the masks where the probe is unsure) with what it ran before
(the probe, then the rays).

    python benchmarks/bench_masks.py [--resolution 640 480] [--repeats 3] [--scenes ...] [--no-write]

For each scene of ``softshadow.scenes.as_built`` (calibration and held
out) and each sample count, ``Exact(samples=N, engine="rays")`` and
``engine="masks"`` are rendered on a prepared scene (the warm-up round
prepares it), medians of ``--repeats`` interleaved rounds of the whole call
and of its ``shadow`` stage. *Same* is the share of the pixels seeing a
surface whose visibility the two engines give bit for bit; *max dV* the
largest difference. *Grain* is the masks' mean |V - box3x3(V)| on the
penumbra pixels less the 1024-sample rays' own (issue 50's noise bar: at
most 0.002). The default call's share of pixels bit for bit the probe and
the rays' (what it ran before) stands beside its time. No Mitsuba: the
rays are the reference here.

A second table times what an error target plans from 1024 samples
(``api.rs``'s ``probed``): ``Exact(samples=N, probe=16, engine="rays")``
(the rays behind the default call's probe) and ``probe=16`` with the
masks behind it against ``engine="masks"`` (every pixel, no probe), with
the share of pixels whose visibility differs between the first and the
last (the probe's misses, and grazing rays) and the largest difference.
Writes
``docs/benchmarks/masks_<W>x<H>.md``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow.scenes.as_built import CALIBRATION, SCENES

SAMPLES = (256, 1024)
#: The planned sample counts of the second table.
PLANNED = (1024, 2500)


def box3(v: np.ndarray) -> np.ndarray:
    p = np.pad(v, 1, mode="edge")
    h, w = v.shape
    return sum(p[j : j + h, i : i + w] for j in range(3) for i in range(3)) / 9.0


def grain(v: np.ndarray, ref: np.ndarray, seen: np.ndarray) -> float:
    """Mean |V - box3x3(V)| over the reference's penumbra pixels, less the reference's own."""
    pen = seen & (ref > 0.0) & (ref < 1.0)
    if not pen.any():
        return 0.0
    return float(np.abs(v - box3(v))[pen].mean() - np.abs(ref - box3(ref))[pen].mean())


def timed(scene: ss.Scene, light: object, camera: ss.Camera, method: object) -> tuple[float, float, ss.Image]:
    t = time.perf_counter()
    img = ss.render(scene, light, camera, method)  # type: ignore[arg-type]
    total = time.perf_counter() - t
    return total, img.timings.get("shadow", float("nan")), img


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--scenes", nargs="*", default=list(SCENES), choices=list(SCENES))
    add_output_arguments(p, DOCS / "masks.md")
    args = p.parse_args()
    res = (args.resolution[0], args.resolution[1])
    if args.out == DOCS / "masks.md":
        args.out = Path(DOCS / f"masks_{res[0]}x{res[1]}.md")
    report = Report(f"exact's engines: rays against masks ({res[0]}×{res[1]})", command_line(__file__))
    report.line(
        "| scene | set | samples | rays ms (shadow) | masks ms (shadow) | rays / masks | same | max dV | grain "
        "| default ms | default / masks | probe + rays ms | probe + rays / default | default same as probe + rays |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        scene, light, camera = SCENES[name](resolution=res)
        # The default call (the probe, then the masks where it is unsure)
        # and what it ran before the masks went behind the probe.
        calls: dict[str, object] = {"default": "auto", "probe rays": ss.Exact(samples=256, probe=16, engine="rays")}
        for n in SAMPLES:
            calls[f"rays {n}"] = ss.Exact(samples=n, engine="rays")
            calls[f"masks {n}"] = ss.Exact(samples=n, engine="masks")
        times: dict[str, list[tuple[float, float]]] = {k: [] for k in calls}
        images: dict[str, ss.Image] = {}
        for k, m in calls.items():  # warm-up: prepares the scene
            images[k] = timed(scene, light, camera, m)[2]
        for _ in range(args.repeats):
            for k, m in calls.items():
                total, shadow, _ = timed(scene, light, camera, m)
                times[k].append((total, shadow))

        def med(k: str, i: int, times: dict[str, list[tuple[float, float]]] = times) -> float:
            return float(np.median([t[i] for t in times[k]])) * 1e3

        seen = np.isfinite(images["rays 256"].depth)
        ref = images["rays 1024"].visibility
        # The default's answer against what it ran before, pixel for pixel.
        kept = float((images["default"].visibility == images["probe rays"].visibility)[seen].mean())
        for n in SAMPLES:
            r, m = images[f"rays {n}"].visibility, images[f"masks {n}"].visibility
            same = float((r == m)[seen].mean())
            dv = float(np.abs(r - m)[seen].max()) if seen.any() else 0.0
            g = grain(m, ref, seen)
            report.line(
                f"| {name} | {'calibration' if name in CALIBRATION else 'held out'} | {n} "
                f"| {med(f'rays {n}', 0):.0f} ({med(f'rays {n}', 1):.0f}) "
                f"| {med(f'masks {n}', 0):.0f} ({med(f'masks {n}', 1):.0f}) "
                f"| {med(f'rays {n}', 0) / med(f'masks {n}', 0):.2f} | {100 * same:.3f}% | {dv:.4f} | {g:+.4f} "
                f"| {med('default', 0):.0f} | {med('default', 0) / med(f'masks {n}', 0):.2f} "
                f"| {med('probe rays', 0):.0f} | {med('probe rays', 0) / med('default', 0):.2f} | {100 * kept:.3f}% |"
            )
    report.line("")
    report.line(
        "| scene | set | samples | probe 16 + rays ms | probe 16 + masks ms | masks ms | probe / masks "
        "| probe + masks / masks | pixels differing | max dV |"
    )
    report.line("|---|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        scene, light, camera = SCENES[name](resolution=res)
        for n in PLANNED:
            pair = {
                "probe": ss.Exact(samples=n, probe=16, engine="rays"),
                "probe masks": ss.Exact(samples=n, probe=16, engine="masks"),
                "masks": ss.Exact(samples=n, engine="masks"),
            }
            imgs = {k: timed(scene, light, camera, m)[2] for k, m in pair.items()}
            t: dict[str, list[float]] = {k: [] for k in pair}
            for _ in range(args.repeats):
                for k, m in pair.items():
                    t[k].append(timed(scene, light, camera, m)[0])
            seen = np.isfinite(imgs["masks"].depth)
            d = np.abs(imgs["masks"].visibility - imgs["probe"].visibility)[seen]
            tp, tpm, tm = (float(np.median(t[k])) * 1e3 for k in ("probe", "probe masks", "masks"))
            report.line(
                f"| {name} | {'calibration' if name in CALIBRATION else 'held out'} | {n} | {tp:.0f} | {tpm:.0f} "
                f"| {tm:.0f} | {tp / tm:.2f} | {tpm / tm:.2f} | {100 * float((d > 0).mean()):.2f}% "
                f"| {float(d.max()) if d.size else 0.0:.4f} |"
            )
    if not args.no_write:
        report.write(
            args.out,
            intro=(
                "Both engines of `exact` on the same shared sample pattern, on the scenes as built "
                "(`softshadow.scenes.as_built`), 2 cores unless the header says otherwise. Times are "
                "whole calls on a prepared scene (medians of interleaved rounds); the shadow stage in "
                "brackets. *same*: pixels seeing a surface whose visibility is bit for bit the rays'. "
                "*grain*: the masks' mean |V - box3x3(V)| over penumbra pixels less the 1024-sample "
                "rays' own. *default*: the default call (a 16-ray probe, then the masks at 256 samples where "
                "it is unsure); *probe + rays*: the probe, then the rays, as the default call ran before. "
                "The second table: what an error target plans from 1024 samples, the rays behind the "
                "probe (and the masks behind it, what a plan below 1024 samples runs) against the masks on every "
                "pixel; *pixels differing*: the rays behind the probe against the masks. *default same as probe + "
                "rays*: the default's visibility bit for bit as the probe and the rays give it."
            ),
        )


if __name__ == "__main__":
    main()
