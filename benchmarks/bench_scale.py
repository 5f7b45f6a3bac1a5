"""Scale: `exact` per shadow ray and the first hits against Mitsuba's
`ray_test` and `ray_intersect` on 125 000- to 2 000 000-triangle scenes, one
mesh and a thousand (issue 29, item 2).

    python benchmarks/bench_scale.py [--resolution 640 480] [--samples 16 64] [--repeats 5]
        [--scenes ...] [--scale 1.0] [--out docs/benchmarks/scale.md] [--no-write]

Scenes (:data:`SCENES`, each at the resolution asked for):

- ``mesh_125k``: one bumpy sphere of about 125 000 triangles floating over a
  closed-box floor, a 1 x 1 rectangle light to its side;
- ``mesh_2m``: the same scene with the sphere tessellated 16 times finer
  (about 2 000 000 triangles): the same pixels and rays, only the triangle
  count changes;
- ``many_meshes``: 1000 spheres, bumpy spheres and tori of 150 to 2000
  triangles each on a box floor;
- ``crowd``: ``softshadow.scenes.as_built.crowd`` (61 meshes, 339 000
  triangles).

``--scale`` shrinks the single meshes' triangle counts and the number of
meshes of ``many_meshes`` (for a quick check; the tables are made at 1).

Per scene and sample count, in rounds (softshadow, then Mitsuba's kernels,
then Mitsuba's whole job) after a warm-up round (the LLVM variant compiles
its kernels there), medians of ``--repeats`` rounds:

- softshadow: ``ss.render(scene, light, cam, method=ss.Exact(samples=n))``,
  every stage of ``img.timings`` and the call's wall clock;
- Mitsuba (``softshadow.reference``'s variant): *first hits*, one
  ``scene.ray_intersect`` of the pixel-centre camera rays
  (``MitsubaEyeJob``'s), evaluating what the job reads of it (``p``, ``n``,
  the hit flag) and the hit mesh; *shadow rays*, ``scene.ray_test(...,
  coherent=False)`` on the rays ``MitsubaEyeJob._shadow`` builds (the same
  batches, stratified PCG32-jittered, ``spawn_ray_to``). Only the kernels are
  timed: the rays are built and evaluated first (Dr.Jit is lazy), then
  ``r = scene.ray_intersect / ray_test(...)``, ``dr.eval(r)``,
  ``dr.sync_thread()``. Its whole job (``MitsubaEyeJob.run``: camera rays,
  first hits, read-back, sampling, shadow rays) is timed beside it.

Each call is also timed first (on a new ``ss.Scene``: nothing prepared) and
following (on the scene the warm-up prepared: the BVH refitted, not built),
beside Mitsuba's scene load and job; the default call's peak memory is
measured in a process of its own. With the default ``--out``, one line a
scene goes into the README between ``<!-- scale-table:start -->`` and
``<!-- scale-table:end -->``.

Rays: the pixels on the light's front side (those Mitsuba's job traces:
every hit pixel for the sun) times the samples, each renderer counting its
own first hits; first hits are counted per pixel of the image. The second
table of each scene fits time = fixed + rays x slope over the sample counts:
what one more ray costs, apart from what a call costs whatever the samples.
"""

from __future__ import annotations

import os

# OpenBLAS threads spin between numpy calls and take cores from the kernels
# being timed (bench_speed.py).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import math
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from _report import DOCS, ROOT, Report, add_output_arguments, command_line, replace_block, runs

import softshadow as ss
from softshadow.reference._mitsuba import _mitsuba
from softshadow.reference.eye_job import BATCH_RAYS, MitsubaEyeJob
from softshadow.scenes.as_built import _camera, crowd, rect_light, slab
from softshadow.scenes.primitives import torus

README = ROOT / "README.md"
# Seconds each timed region waits for the other renderer's threads to idle.
SETTLE_S = 0.05
START, END = "<!-- scale-table:start -->", "<!-- scale-table:end -->"

Mesh = tuple[np.ndarray, np.ndarray]
EyeScene = tuple[ss.Scene, Any, ss.Camera]


# --------------------------------------------------------------------------
# Scenes
# --------------------------------------------------------------------------


def bumpy_sphere(center: tuple[float, float, float], radius: float, n: int, bumps: float = 0.12, seed: int = 0) -> Mesh:
    """A closed UV sphere of ``n`` segments and ``n // 2`` rings
    (2 n (n // 2 - 1), about n² triangles), its radius modulated by
    ``bumps`` so that the bumps shadow each other; numpy only."""
    rings = max(n // 2, 3)
    rng = np.random.default_rng(seed)
    k1, k2, phase = int(rng.integers(4, 8)), int(rng.integers(4, 9)), float(rng.uniform(0, 2 * np.pi))
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1.0 + bumps * np.sin(k1 * t) * np.cos(k2 * p + phase)
    ring = np.stack([r * np.sin(t) * np.cos(p), r * np.cos(t), r * np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    verts = np.vstack([[0.0, 1.0, 0.0], ring, [0.0, -1.0, 0.0]]) * radius + np.asarray(center)
    top, bottom = 0, len(verts) - 1
    s = np.arange(n)
    s1 = (s + 1) % n
    caps = [
        np.stack([np.full(n, top), 1 + s1, 1 + s], axis=1),
        np.stack([np.full(n, bottom), 1 + (rings - 2) * n + s, 1 + (rings - 2) * n + s1], axis=1),
    ]
    rr, seg = np.meshgrid(np.arange(rings - 2), s, indexing="ij")
    a = 1 + rr * n + seg
    b = 1 + rr * n + (seg + 1) % n
    c = b + n
    d = a + n
    quads = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return verts, np.concatenate([*caps, quads]).astype(np.uint32)


def _segments(triangles: float) -> int:
    """Segments of a :func:`bumpy_sphere` of about ``triangles`` triangles."""
    return max(8, round(1 + math.sqrt(1 + triangles)))


def _single_mesh(resolution: tuple[int, int], triangles: float) -> EyeScene:
    meshes = [bumpy_sphere((0.0, 0.85, 0.0), 0.6, _segments(triangles)), slab()]
    light = rect_light((1.5, 3.5, 1.0), (0.0, 0.0, 0.0), (1.0, 1.0))
    return ss.Scene(meshes=meshes), light, _camera((2.2, 1.6, 2.8), (0.0, 0.6, 0.0), resolution, 38.0)


def many_meshes(resolution: tuple[int, int], count: int = 1000) -> EyeScene:
    """``count`` spheres, bumpy spheres and tori of 150 to 2000 triangles
    each (mostly small: their counts log-distributed, skewed low), scattered
    on a grid over a box floor, touching and intersecting each other."""
    rng = np.random.default_rng(29)
    side = math.ceil(math.sqrt(count))
    spacing = 8.0 / side
    meshes = [slab(0.0, 5.0)]
    for k in range(count):
        i, j = divmod(k, side)
        x = -4.0 + spacing * (i + 0.5) + float(rng.uniform(-0.3, 0.3)) * spacing
        z = -4.0 + spacing * (j + 0.5) + float(rng.uniform(-0.3, 0.3)) * spacing
        size = spacing * float(rng.uniform(0.3, 0.6))
        tris = 150.0 * (2000.0 / 150.0) ** (float(rng.random()) ** 2)
        if k % 3 == 2:
            minor = max(6, round(math.sqrt(tris / 2 / 2.5)))
            meshes.append(torus((x, 0.35 * size, z), size * 0.7, size * 0.3, round(tris / 2 / minor), minor))
        else:
            bumps = 0.15 if k % 3 == 1 else 0.0
            meshes.append(bumpy_sphere((x, size * 0.9, z), size, _segments(tris), bumps=bumps, seed=k))
    light = rect_light((2.5, 7.0, 1.5), (0.0, 0.0, 0.0), (1.2, 1.2))
    return ss.Scene(meshes=meshes), light, _camera((5.5, 4.5, 6.0), (0.0, 0.0, 0.0), resolution, 45.0)


def scenes(scale: float) -> dict[str, Callable[[tuple[int, int]], EyeScene]]:
    """The scenes by name, their triangle (or mesh) counts times ``scale``."""
    return {
        "mesh_125k": lambda res: _single_mesh(res, 125_000 * scale),
        "mesh_2m": lambda res: _single_mesh(res, 2_000_000 * scale),
        "many_meshes": lambda res: many_meshes(res, max(1, round(1000 * scale))),
        "crowd": crowd,
    }


SCENES = tuple(scenes(1.0))


# --------------------------------------------------------------------------
# Mitsuba's kernels alone
# --------------------------------------------------------------------------


class MitsubaKernels:
    """``ray_intersect`` on the camera rays and ``ray_test`` on the shadow
    rays of a :class:`MitsubaEyeJob`, each timed alone."""

    def __init__(self, job: MitsubaEyeJob) -> None:
        self.job = job
        mi, dr = job.mi, job.dr
        w, h = job.w, job.h
        idx = dr.arange(mi.UInt32, w * h)
        pos = mi.Point2f((mi.Float(idx % w) + 0.5) / w, (mi.Float(idx // w) + 0.5) / h)
        self.camera_rays, _ = job.sensor.sample_ray(0.0, 0.0, pos, mi.Point2f(0.5, 0.5))
        dr.eval(self.camera_rays)
        dr.sync_thread()
        # The first hits the shadow rays start from, as the job finds them.
        si = job.scene.ray_intersect(self.camera_rays)
        hit = np.asarray(si.is_valid().numpy(), dtype=bool)
        self.p = np.asarray(si.p.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        self.n = np.asarray(si.n.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        lit = np.ones(len(self.p), dtype=bool) if job.sun else (self.p - job.center) @ job.n > 0
        self.lit = np.flatnonzero(lit)
        self.hits = int(hit.sum())

    def first_hits(self) -> float:
        """Seconds of one ``ray_intersect`` of every camera ray."""
        dr = self.job.dr
        t = time.perf_counter()
        si = self.job.scene.ray_intersect(self.camera_rays)
        dr.eval(si.p, si.n, si.t, si.shape)
        dr.sync_thread()
        return time.perf_counter() - t

    def shadow(self, samples: int) -> float:
        """Seconds of ``ray_test`` over the job's shadow rays at ``samples``
        per lit pixel, in the job's batches, the rays built beforehand."""
        dr = self.job.dr
        a, b = self.job.strata(samples)
        per = max(1, BATCH_RAYS // samples)
        seconds = 0.0
        for first in range(0, len(self.lit), per):
            sel = self.lit[first : first + per]
            ray = self.job.shadow_rays(self.p[sel], self.n[sel], samples, a, b, first)
            dr.eval(ray)
            dr.sync_thread()
            t = time.perf_counter()
            r = self.job.scene.ray_test(ray, coherent=False)
            dr.eval(r)
            dr.sync_thread()
            seconds += time.perf_counter() - t
            del ray, r
        return seconds


# --------------------------------------------------------------------------
# Measurement
# --------------------------------------------------------------------------


@dataclass
class Times:
    """Every round's seconds, by what was timed."""

    ours: dict[str, list[float]] = field(default_factory=dict)
    mitsuba: dict[str, list[float]] = field(default_factory=dict)
    lit_ours: int = 0
    vis_ours: float = 0.0
    vis_mitsuba: float = 0.0

    def add(self, which: dict[str, list[float]], key: str, seconds: float) -> None:
        which.setdefault(key, []).append(seconds)


def lit_pixels(img: Any, light: Any) -> int:
    """Pixels that see a surface on the light's front side (every one for
    the sun): those Mitsuba's job sends shadow rays from."""
    if isinstance(light, ss.DirectionalLight):
        return int(img.mask.sum())
    p = img.position[img.mask]
    return int(((p - np.asarray(light.center)) @ np.asarray(light.n) > 0).sum())


def settle() -> None:
    """Lets the other renderer's worker threads go idle before a timed region.

    Dr.Jit's workers keep the cores busy for a while after a Mitsuba job
    ends (and rayon's briefly after ours): without a pause, softshadow's
    64-sample first hits, timed right after Mitsuba's 16-sample job, read
    17-30 ms where alone they take 9 (mesh_125k).
    """
    time.sleep(SETTLE_S)


def median_ms(xs: list[float]) -> float:
    return float(np.median(xs)) * 1e3


def ns(ms: float, count: int) -> str:
    return f"{ms * 1e6 / count:.0f}" if count else "–"


def ratio(mitsuba_ms: float, ours_ms: float) -> str:
    return f"{mitsuba_ms / ours_ms:.2f}" if ours_ms > 0 else "–"


def _status_gib(field: str = "VmRSS") -> float:
    """A memory field of /proc/self/status in GiB: ``VmRSS`` (now) or ``VmHWM``
    (the peak of this process image; ``ru_maxrss`` would keep the peak of the
    process that forked it)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 2**20
    return float("nan")


def call_memory(name: str, res: tuple[int, int], scale: float) -> tuple[float, float]:
    """The default call's first render of scene ``name`` in a process of
    its own (nothing else there has peaked): its peak resident memory above
    what the process held before the call, and the peak, in GiB."""
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]); import bench_scale as b, softshadow as ss; "
        "s, l, c = b.scenes(float(sys.argv[3]))[sys.argv[2]]((int(sys.argv[4]), int(sys.argv[5]))); "
        "before = b._status_gib(); ss.render(s, l, c); "
        "peak = b._status_gib('VmHWM'); print(peak - before, peak)"
    )
    here = str(Path(__file__).resolve().parent)
    out = subprocess.run(
        [sys.executable, "-c", code, here, name, str(scale), str(res[0]), str(res[1])],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return float(out[0]), float(out[1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--samples", type=int, nargs="+", default=[16, 64])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--scenes", nargs="*", default=list(SCENES), choices=SCENES)
    p.add_argument("--scale", type=float, default=1.0, help="triangle and mesh counts times this (quick checks)")
    add_output_arguments(p, DOCS / "scale.md")
    args = p.parse_args()
    res = (args.resolution[0], args.resolution[1])
    builders = scenes(args.scale)
    report = Report(f"Scale: exact and first hits against Mitsuba ({res[0]}×{res[1]})", command_line(__file__))
    _mitsuba()  # selects the variant before any timing
    pixels = res[0] * res[1]
    summary: list[str] = []
    prepared: list[str] = []
    readme: list[str] = []
    for name in args.scenes:
        call_gib, peak_gib = call_memory(name, res, args.scale)
        scene, light, cam = builders[name](res)
        counts = [len(f) for _, f in scene.meshes]
        t = time.perf_counter()
        job = MitsubaEyeJob(scene, light, cam)
        load_ms = (time.perf_counter() - t) * 1e3
        kernels = MitsubaKernels(job)
        print(f"{name}: {scene.triangle_count} triangles in {len(scene.meshes)} meshes", flush=True)
        times = {n: Times() for n in args.samples}
        # First calls (a new Scene: nothing prepared) and following ones (the
        # scene prepared by the warm-up round), of each method.
        calls: dict[str, dict[str, list[float]]] = {}
        methods: dict[str, Any] = {f"exact {n}": ss.Exact(samples=n) for n in args.samples}
        methods["default"] = "auto"
        threads = 0
        for round_ in range(args.repeats + 1):  # round 0: the warm-up
            for label, method in methods.items():
                for kind, s in (("first", ss.Scene(meshes=scene.meshes)), ("following", scene)):
                    settle()
                    t = time.perf_counter()
                    ss.render(s, light, cam, method=method)
                    if round_ > 0:
                        calls.setdefault(label, {}).setdefault(kind, []).append(time.perf_counter() - t)
            for n in args.samples:
                tm = times[n]
                settle()
                t = time.perf_counter()
                img = ss.render(scene, light, cam, method=ss.Exact(samples=n))
                wall = time.perf_counter() - t
                settle()
                mh = kernels.first_hits()
                settle()
                ms = kernels.shadow(n)
                settle()
                t = time.perf_counter()
                vis = job.run(n)
                job_s = time.perf_counter() - t
                if round_ == 0:
                    tm.lit_ours = lit_pixels(img, light)
                    tm.vis_ours = float(img.visibility[img.mask].mean())
                    tm.vis_mitsuba = float(vis[img.mask].mean())
                    threads = img.threads
                    continue
                for stage, s in img.timings.items():
                    tm.add(tm.ours, stage, s)
                tm.add(tm.ours, "call", wall)
                tm.add(tm.mitsuba, "first_hits", mh)
                tm.add(tm.mitsuba, "shadow", ms)
                tm.add(tm.mitsuba, "job", job_s)
        report.line(f"## {name}")
        report.line()
        report.line(
            f"{scene.triangle_count} triangles in {len(scene.meshes)} meshes ({min(counts)} to {max(counts)} "
            f"a mesh); {type(light).__name__}; {kernels.hits / pixels:.0%} of the pixels see a surface, "
            f"{len(kernels.lit) / pixels:.0%} on the light's front side (Mitsuba's first hits; softshadow's: "
            f"{times[args.samples[0]].lit_ours / pixels:.0%}). Mitsuba's scene load (its BVH build, outside "
            f"every Mitsuba time below): {load_ms:.0f} ms; softshadow's stages below are those of a call on the "
            f"prepared scene (its BVH refitted, not built: the next table has both; `{threads}` threads)."
        )
        report.line()
        report.line(
            "| samples | stage | softshadow (ms) | Mitsuba (ms) | softshadow ns / ray | Mitsuba ns / ray "
            "| Mitsuba time / softshadow time |"
        )
        report.line("|---|---|---|---|---|---|---|")
        fits: dict[str, list[tuple[int, float]]] = {"ours": [], "mitsuba": []}
        per_ray: dict[int, str] = {}
        default_calls = (0.0, 0.0)
        for n in args.samples:
            tm = times[n]
            ours = {k: median_ms(v) for k, v in tm.ours.items()}
            theirs = {k: median_ms(v) for k, v in tm.mitsuba.items()}
            rays_ours, rays_theirs = tm.lit_ours * n, len(kernels.lit) * n
            fits["ours"].append((rays_ours, ours.get("shadow", 0.0)))
            fits["mitsuba"].append((rays_theirs, theirs["shadow"]))
            # The stages Mitsuba has a kernel for: its time and what each counts.
            compared = {
                "first_hits": ("first hits (per pixel)", theirs["first_hits"], pixels, pixels),
                "shadow": ("shadow rays (per ray)", theirs["shadow"], rays_ours, rays_theirs),
            }
            per_ray[n] = ratio(theirs["shadow"] / max(rays_theirs, 1), ours.get("shadow", 0.0) / max(rays_ours, 1))
            for stage, v in ours.items():
                if stage == "call":
                    continue
                if stage not in compared:
                    report.line(f"| {n} | {stage} | {v:.1f} | | | | |")
                    continue
                label, m, count_ours, count_theirs = compared[stage]
                cells = f"{ns(v, count_ours)} | {ns(m, count_theirs)} | {ratio(m, v)}"
                report.line(f"| {n} | {label} | {v:.1f} | {m:.1f} | {cells} |")
                summary.append(f"| {name} | {n} | {label} | {cells} |")
            report.line(
                f"| {n} | whole call: `ss.render` / `MitsubaEyeJob.run` | {ours['call']:.1f} | {theirs['job']:.1f} "
                f"| | | {ratio(theirs['job'], ours['call'])} |"
            )
        report.line()
        report.line(
            "Mean visibility over the pixels that see a surface: "
            + "; ".join(
                f"{n} samples: softshadow {times[n].vis_ours:.4f}, Mitsuba {times[n].vis_mitsuba:.4f}"
                for n in args.samples
            )
            + "."
        )
        report.line()
        report.line(
            "Prepare once, render many: the whole call on a new `ss.Scene` (nothing prepared: the triangles "
            "gathered and checked, the shadow rays' BVH built) and on the scene the earlier rounds prepared "
            "(the kept BVH refitted to the call's light space), beside Mitsuba's scene load and job."
        )
        report.line()
        report.line(
            "| call | first (ms) | following (ms) | following / first | Mitsuba load + job (ms) | Mitsuba job (ms) |"
        )
        report.line("|---|---|---|---|---|---|")
        for label, kinds in calls.items():
            first, following = median_ms(kinds["first"]), median_ms(kinds["following"])
            n = int(label.split()[1]) if label.startswith("exact") else None
            job_ms = median_ms(times[n].mitsuba["job"]) if n is not None else None
            mitsuba = f"{load_ms + job_ms:.0f} | {job_ms:.0f}" if job_ms is not None else " | "
            report.line(f"| {label} | {first:.0f} | {following:.0f} | {following / first:.2f} | {mitsuba} |")
            prepared.append(f"| {name} | {label} | {first:.0f} | {following:.0f} | {following / first:.2f} |")
            if label == "default":
                default_calls = (first, following)
        n_max = max(args.samples)
        readme.append(
            f"| {name} | {scene.triangle_count:,} in {len(scene.meshes)} | {per_ray[n_max]} | "
            f"{default_calls[0]:.0f} | {default_calls[1]:.0f} | {call_gib:.2f} |"
        )
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
        report.line()
        report.line(
            f"Memory: the default call's first render, in a process of its own, peaked {call_gib:.2f} GiB above "
            f"what the process held before it ({peak_gib:.2f} GiB in all); this benchmark's process, Mitsuba's "
            f"scenes included, has peaked at {peak:.2f} GiB so far."
        )
        report.line()
        if len(args.samples) >= 2:
            report.line(
                "What the sample count costs: shadow-ray time = fixed + rays × slope, fitted over the sample counts."
            )
            report.line()
            report.line("| renderer | fixed (ms) | slope (ns / ray) |")
            report.line("|---|---|---|")
            for who, label in (("ours", "softshadow `shadow`"), ("mitsuba", "Mitsuba `ray_test`")):
                xs, ys = zip(*fits[who], strict=True)
                slope, fixed = np.polyfit(np.asarray(xs, dtype=float), np.asarray(ys, dtype=float), 1)
                report.line(f"| {label} | {fixed:.1f} | {slope * 1e6:.0f} |")
            report.line()
    report.line("## Summary")
    report.line()
    report.line("| scene | samples | stage | softshadow ns | Mitsuba ns | Mitsuba time / softshadow time |")
    report.line("|---|---|---|---|---|---|")
    for row in summary:
        report.line(row)
    report.line()
    report.line("| scene | call | first (ms) | following (ms) | following / first |")
    report.line("|---|---|---|---|---|")
    for row in prepared:
        report.line(row)
    if args.no_write:
        return
    intro = (
        f"Times are medians of {runs(args.repeats)} after a warm-up round, softshadow and Mitsuba "
        f"alternating within each round, each timed region after a {SETTLE_S * 1e3:.0f} ms pause (the other "
        "renderer's worker threads stay busy for a while after its job). softshadow: the stages of `img.timings` of "
        "`ss.render(..., method=ss.Exact(samples=n))` on a prepared scene (`first hits` rasterizes the "
        "camera's view; `refit` fits the BVH kept from an earlier call to this call's light space, where a "
        "first call's `bvh` builds it; `shadow` traces the rays). "
        "Mitsuba: `ray_intersect` on the pixel-centre camera rays and `ray_test(..., coherent=False)` on "
        "the shadow rays `MitsubaEyeJob` builds, the kernels alone (the rays built and evaluated first); "
        "its whole eye-view job beside them. *Rays*: the pixels on the light's front side times the "
        "samples, each renderer counting its own first hits; first hits are per pixel of the image. "
        "A ratio above 1 means softshadow is faster."
    )
    report.write(args.out, intro=intro)
    if args.out != DOCS / "scale.md":
        return
    n_max = max(args.samples)
    table = [
        f"| scene ({res[0]}×{res[1]}) | triangles in meshes | `exact` per shadow ray, Mitsuba's `ray_test` time / ours "
        f"({n_max} samples) | default call, first (ms) | following (ms) | its peak memory (GiB) |",
        "|---|---|---|---|---|---|",
        *readme,
    ]
    replace_block(README, START, END, table)


if __name__ == "__main__":
    main()
