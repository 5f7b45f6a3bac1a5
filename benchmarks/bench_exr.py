"""EXR compressions for dataset items: time to write and read, file size.

    python benchmarks/bench_exr.py [--resolution 640 480] [--repeats 7] [--no-write]

The channels of one eye-view image (``softshadow.scenes.eye_view`` bunny_on_floor,
``ss.render``'s default method: visibility, shaded and unshadowed RGB,
depth, normal, mesh id, mask; 16 float32 channels), written with each
compression ``softshadow.io.write_exr`` takes (``outputs.compression`` of a
dataset spec) and read back with ``softshadow.io.read_exr``: medians of
``--repeats`` writes and reads on one thread of this process, the file's
size, and whether the pixels read back equal the pixels written. Prints the
table and writes it to ``docs/benchmarks/exr.md``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss
from softshadow import io
from softshadow.scenes.eye_view import EYE_SCENES


def same_pixels(written: dict[str, np.ndarray], read: dict[str, np.ndarray]) -> bool:
    """Whether every channel read back equals the one written (OpenEXR groups
    ``x.R/G/B`` into one (H, W, 3) channel ``x``; NaN equals NaN)."""
    for name, a in written.items():
        group, _, c = name.rpartition(".")
        b = read[group][..., "RGB".index(c)] if c in ("R", "G", "B") and group in read else read[name]
        if not np.array_equal(a, b, equal_nan=True):
            return False
    return True


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--repeats", type=int, default=7)
    add_output_arguments(p, DOCS / "exr.md")
    a = p.parse_args()
    res = (a.resolution[0], a.resolution[1])
    scene, light, camera = EYE_SCENES["bunny_on_floor"](res)
    channels = {
        k: np.ascontiguousarray(v, dtype=np.float32) for k, v in ss.render(scene, light, camera).channels().items()
    }
    report = Report(
        f"EXR compressions ({res[0]}×{res[1]}, {len(channels)} float32 channels)", command_line(__file__), mitsuba=False
    )
    report.line("| compression | write (ms) | read (ms) | size (MB) | pixels read back equal |")
    report.line("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="bench_exr_") as tmp:
        for name in io.EXR_COMPRESSIONS:
            try:
                io.exr_compression(name)
            except ValueError as e:
                report.line(f"| {name} | {e} | | | |")
                continue
            path = Path(tmp) / f"{name}.exr"
            writes, reads = [], []
            for _ in range(a.repeats):
                t = time.perf_counter()
                io.write_exr(path, channels, compression=name)
                writes.append(time.perf_counter() - t)
                t = time.perf_counter()
                back = io.read_exr(path)
                reads.append(time.perf_counter() - t)
            report.line(
                f"| {name} | {1e3 * np.median(writes):.1f} | {1e3 * np.median(reads):.1f} "
                f"| {path.stat().st_size / 1e6:.2f} | {'yes' if same_pixels(channels, back) else '**no**'} |"
            )
    if not a.no_write:
        report.write(a.out, intro=(__doc__ or "").split("\n\n", 2)[2].strip())


if __name__ == "__main__":
    main()
