"""Per-stage times of the GPU backend, from meshes to visibility.

    python benchmarks/bench_gpu.py [--resolutions 256 512 1024 2048] [--method ssm]
                                   [--occluder-resolution 256] [--repeats 1]
                                   [--out docs/benchmarks/gpu_lavapipe.md] [--no-write]

For the bunny (16k triangles) and trimesh icospheres of 328k and 1.3M
triangles floating over the floor (light 1x1 at distance 4), at each map
resolution: the stages the GPU backend reports (CPU: transform, extent,
triangle set-up, upload, encoding; device: the rasterization of receivers and
occluders, the row statistics and the shading, from timestamp queries where
the adapter has them, else one wall time for the whole submission; then the
readback), the end-to-end wall time, and the CPU backend's end-to-end time on
the same input. The occluder maps are at most --occluder-resolution (the
SSM's cost grows with the square of the occluder texels per penumbra). The
first call, which compiles the pipelines, is not timed. The table names the
adapter (a software one, such as lavapipe, renders on the CPU: its numbers
say nothing about a GPU's).

Prints the markdown table and writes it to ``docs/benchmarks/gpu_lavapipe.md``
(or ``--out``: name the file after the adapter) with a header naming the
command, the machine and the date (``--no-write``: print only).
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial

import numpy as np
from _report import DOCS, Report, add_output_arguments, command_line, describe, runs

import softshadow as ss
from softshadow import scenes

DEVICE_STAGES = ("gpu_raster_receivers", "gpu_raster_occluders", "gpu_row_stats", "gpu_shadow")


def sphere_scene(subdivisions: int) -> tuple[ss.Scene, ss.RectLight]:
    import trimesh

    s = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.5)
    v = np.asarray(s.vertices) + np.array([0.0, 1.5, 0.0])
    return ss.Scene(occluders=[(v, np.asarray(s.faces))], receivers=[scenes.floor()]), scenes.default_light()


def timed(fn):
    t = time.perf_counter()
    r = fn()
    return r, time.perf_counter() - t


def row(name: str, scene: ss.Scene, light: ss.RectLight, res: int, a: argparse.Namespace) -> list[str]:
    """One table row: the GPU's stage times (median end-to-end run) and the CPU's end to end."""
    kw = dict(resolution=res, occluder_resolution=min(res, a.occluder_resolution), method=a.method, passes=2)
    runs = [timed(partial(ss.soft_shadow_map, scene, light, backend="gpu", **kw)) for _ in range(a.repeats)]
    runs.sort(key=lambda r: r[1])
    sm, wall = runs[len(runs) // 2]
    cpu_sm, cpu_wall = timed(partial(ss.soft_shadow_map, scene, light, backend="cpu", **kw))
    if sm.backend != "gpu" or cpu_sm.backend != "cpu" or sm.method != cpu_sm.method:
        raise SystemExit(f"{name} {res}²: ran {sm.method!r} on {sm.backend}, {cpu_sm.method!r} on {cpu_sm.backend}")
    t = sm.timings
    out = [name, f"{len(scene.occluder_mesh[1])}", f"{res}²", describe(sm), f"{1e3 * (t['setup'] + t['upload']):.1f}"]
    if any(s in t for s in DEVICE_STAGES):
        out += [f"{1e3 * t[s]:.1f}" for s in DEVICE_STAGES]
    else:  # no timestamp queries: one wall time for the submission
        out += ["—"] * (len(DEVICE_STAGES) - 1) + [f"{1e3 * t['gpu']:.1f} (all, wall)"]
    return out + [f"{1e3 * t['readback']:.1f}", f"{1e3 * wall:.0f}", f"{1e3 * cpu_wall:.0f}"]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[256, 512, 1024, 2048])
    p.add_argument("--method", default="ssm", choices=["ssm", "bitmask"])
    p.add_argument("--occluder-resolution", type=int, default=256)
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--spheres", type=int, nargs="*", default=[7, 8], help="icosphere subdivisions")
    add_output_arguments(p, DOCS / "gpu_lavapipe.md")
    a = p.parse_args(argv)

    info = ss.gpu_info()
    kind = "a software renderer on the CPU" if info["software"] else info["device_type"]
    report = Report(f"GPU backend stages on {info['name']}", command_line(__file__, argv), mitsuba=False)
    report.line(f"Adapter: {info['name']} ({kind}; {info['driver']}; {info['backend']}).")
    report.line()
    cols = ["scene", "triangles", "map", "what ran", "setup+upload (ms)"]
    cols += [s.removeprefix("gpu_") + " (ms)" for s in DEVICE_STAGES]
    cols += ["readback (ms)", "GPU end to end (ms)", "CPU backend end to end (ms)"]
    report.line("| " + " | ".join(cols) + " |")
    report.line("|" + "---|" * len(cols))
    cases = [("bunny", scenes.bunny_floating())] + [(f"icosphere({k})", sphere_scene(k)) for k in a.spheres]
    for name, (scene, light) in cases:
        # The first call compiles the pipelines: not timed.
        ss.soft_shadow_map(scene, light, resolution=32, method=a.method, backend="gpu")
        for res in a.resolutions:
            report.line("| " + " | ".join(row(name, scene, light, res, a)) + " |")

    if not a.no_write:
        software = (
            f" **{info['name']} renders on the CPU: these numbers show the stages and how they scale, "
            "not what a GPU does.**"
            if info["software"]
            else ""
        )
        report.write(
            a.out,
            intro=(
                f'`method="{a.method}"`, two passes, occluder maps at most {a.occluder_resolution}²; the bunny '
                "(16k triangles) and trimesh icospheres floating over the floor. GPU times are the median of "
                f"{runs(a.repeats)} after a warm-up call that compiles the pipelines; "
                "the CPU backend's is one run on the same input. Device stages are from timestamp queries "
                "(one wall time for the submission where the adapter has none); milliseconds." + software
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
