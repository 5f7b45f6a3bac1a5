"""Per-stage times of the GPU backend, from meshes to visibility.

    python benchmarks/bench_gpu.py [--resolutions 256 512 1024 2048] [--method ssm]
                                   [--occluder-resolution 256] [--repeats 1]

For the bunny (16k triangles) and trimesh icospheres of 328k and 1.3M
triangles floating over the floor (light 1x1 at distance 4), at each map
resolution: the stages the GPU backend reports (CPU: transform, extent,
triangle set-up, upload, encoding; device: the rasterization of receivers and
occluders, the row statistics and the shading, from timestamp queries where
the adapter has them, else one wall time for the whole submission; then the
readback), the end-to-end wall time, and the CPU backend's end-to-end time on
the same input. The occluder maps are at most --occluder-resolution (the
SSM's cost grows with the square of the occluder texels per penumbra). The
first call, which compiles the pipelines, is not timed. Prints a markdown
table; names the adapter (a software one, such as lavapipe, renders on the
CPU: its numbers say nothing about a GPU's).
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from functools import partial

import numpy as np

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
    _, cpu_wall = timed(partial(ss.soft_shadow_map, scene, light, backend="cpu", **kw))
    t = sm.timings
    out = [name, f"{len(scene.occluder_mesh[1])}", f"{res}²", f"{1e3 * (t['setup'] + t['upload']):.1f}"]
    if any(s in t for s in DEVICE_STAGES):
        out += [f"{1e3 * t[s]:.1f}" for s in DEVICE_STAGES]
    else:  # no timestamp queries: one wall time for the submission
        out += ["—"] * (len(DEVICE_STAGES) - 1) + [f"{1e3 * t['gpu']:.1f} (all, wall)"]
    return out + [f"{1e3 * t['readback']:.1f}", f"{1e3 * wall:.0f}", f"{1e3 * cpu_wall:.0f}"]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolutions", type=int, nargs="+", default=[256, 512, 1024, 2048])
    p.add_argument("--method", default="ssm", choices=["ssm", "bitmask"])
    p.add_argument("--occluder-resolution", type=int, default=256)
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--spheres", type=int, nargs="*", default=[7, 8], help="icosphere subdivisions")
    a = p.parse_args()

    info = ss.gpu_info()
    kind = "software renderer on the CPU" if info["software"] else info["device_type"]
    cpu = platform.processor() or platform.machine()
    print(f"# GPU backend: {info['name']} ({kind}; {info['driver']}); host {cpu}, {os.cpu_count()} cores")
    print(f"# method {a.method}, occluder maps at most {a.occluder_resolution}^2, median of {a.repeats}")
    print()
    cols = ["scene", "triangles", "map", "setup+upload (ms)"]
    cols += [s.removeprefix("gpu_") + " (ms)" for s in DEVICE_STAGES]
    cols += ["readback (ms)", "GPU end to end (ms)", "CPU backend end to end (ms)"]
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    cases = [("bunny", scenes.bunny_floating())] + [(f"icosphere({k})", sphere_scene(k)) for k in a.spheres]
    for name, (scene, light) in cases:
        # The first call compiles the pipelines: not timed.
        ss.soft_shadow_map(scene, light, resolution=32, method=a.method, backend="gpu")
        for res in a.resolutions:
            print("| " + " | ".join(row(name, scene, light, res, a)) + " |", flush=True)


if __name__ == "__main__":
    main()
