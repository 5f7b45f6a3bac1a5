"""The eye view against Mitsuba: every method's time and error on the eye-view
scenes, and Mitsuba's time at equal error.

    python benchmarks/bench_eye.py [--resolution 640 480] [--repeats 7] [--scenes ...] [--no-write]

For each scene of ``softshadow.eye_scenes.EYE_SCENES`` at the resolution:

* the reference: ``softshadow.reference.render_visibility`` with
  ``--reference-samples`` (4096) stratified light samples per pixel;
* Mitsuba's whole eye-view job at 1, 4, 16, 64 and 256 samples, as a Mitsuba user
  writes it: pixel-centre camera rays from the sensor, ``ray_intersect``,
  then per hit pixel the samples' shadow rays (stratified, jittered by
  Dr.Jit's PCG32, spawned with ``spawn_ray_to`` / ``spawn_ray``) and
  ``ray_test``, all in Dr.Jit arrays; its time (median of ``--repeats``
  after a warm-up that compiles the kernels) and its error;
* every call of ``CALLS``: ``softshadow.render`` end to end from the meshes
  (the G-buffer, the light space, the maps or rays, the shading), its time
  and error, and Mitsuba's time at that error, interpolated log-log between
  its sample counts († where one sample a pixel already does as well, *
  where it extrapolates).

The error is the mean |V - V_ref| over the pixels where both renderers see
the same mesh at the same place (``softshadow.metrics.compare_images``).
Each round times every call and every Mitsuba sample count once, so both
sides of a ratio see the same load, in an order reversed every other round
so that neither always runs right after the other. Prints the tables, writes them to
``docs/benchmarks/eye.md`` and one row per scene (the fastest call within
``BAR_ERROR`` and its ratio to Mitsuba at that error) into the README
between ``<!-- eye-table:start -->`` and ``<!-- eye-table:end -->``.
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Any

import numpy as np
from _report import DOCS, ROOT, Report, add_output_arguments, command_line, runs

import softshadow as ss
from softshadow.experiments.study import Point, mitsuba_seconds_at
from softshadow.eye_scenes import EYE_SCENES
from softshadow.metrics import compare_images
from softshadow.reference import render_visibility
from softshadow.reference._mitsuba import _mitsuba, _mitsuba_mesh
from softshadow.reference.camera import camera_sensor

README = ROOT / "README.md"
START, END = "<!-- eye-table:start -->", "<!-- eye-table:end -->"
BAR_ERROR = 0.02
#: 1 and 4 besides the issue's 16, 64 and 256: Mitsuba's error at low counts
#: is small on this metric (most pixels are fully lit or in umbra, which one
#: sample gets right), and extrapolating below 16 would undercut its real
#: floor, the first hits plus one ray a pixel.
MITSUBA_SAMPLES = (1, 4, 16, 64, 256)
CALLS: list[tuple[str, Any]] = [
    ("auto", "auto"),
    ("ssm", "ssm"),
    ("bitmask 64", ss.Bitmask(samples=64)),
    ("bitmask 256", ss.Bitmask(samples=256)),
    ("exact 16", ss.Exact(samples=16)),
    ("exact 64", ss.Exact(samples=64)),
    ("pcss", ss.Pcss()),
    ("smoothies", ss.Smoothies()),
    ("shadow map", ss.ShadowMapping()),
    ("shadow map, PCF 3", ss.ShadowMapping(filter=ss.PCF(size=3), bias=ss.SlopeScaleBias(slope=4))),
    ("shadow map, blur 4", ss.ShadowMapping(blur=ss.EyeSpaceBlur(iterations=4))),
]
#: Rays per Dr.Jit launch: keeps the ray arrays to a few hundred MB.
BATCH_RAYS = 1 << 23


class MitsubaJob:
    """Mitsuba's eye-view job on one scene, its scene and sensor loaded once."""

    def __init__(self, scene: ss.Scene, light: Any, camera: ss.Camera) -> None:
        mi, dr = _mitsuba()
        self.mi, self.dr = mi, dr
        d: dict[str, Any] = {"type": "scene"}
        for k, (v, f) in enumerate(scene.meshes):
            d[f"mesh_{k}"] = _mitsuba_mesh(mi, f"mesh_{k}", v.astype(np.float32), f)
        self.scene = mi.load_dict(d)
        self.sensor = mi.load_dict(camera_sensor(camera))
        self.w, self.h = camera.resolution
        self.sun = isinstance(light, ss.DirectionalLight)
        if self.sun:
            self.n, self.u, self.v = light.n, light.u, light.v
            self.size = tuple(2 * math.tan(math.radians(a) / 2) for a in light.angular_size)
            self.center = self.n
        else:
            self.n, self.u, self.v = light.n, light.u, light.v
            self.size = light.size
            self.center = np.asarray(light.center)

    def run(self, samples: int) -> np.ndarray:
        """The visibility image (H, W) at ``samples`` per pixel."""
        mi, dr = self.mi, self.dr
        w, h = self.w, self.h
        idx = dr.arange(mi.UInt32, w * h)
        pos = mi.Point2f((mi.Float(idx % w) + 0.5) / w, (mi.Float(idx // w) + 0.5) / h)
        ray, _ = self.sensor.sample_ray(0.0, 0.0, pos, mi.Point2f(0.5, 0.5))
        si = self.scene.ray_intersect(ray)
        hit = np.asarray(si.is_valid().numpy(), dtype=bool)
        p = np.asarray(si.p.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        n = np.asarray(si.n.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        if self.sun:
            lit = np.ones(len(p), dtype=bool)
        else:
            lit = (p - self.center) @ self.n > 0
        vis = np.zeros(len(p), dtype=np.float32)
        small = int(math.isqrt(samples))
        while samples % small:
            small -= 1
        a, b = (samples // small, small) if self.size[0] >= self.size[1] else (small, samples // small)
        chosen = np.flatnonzero(lit)
        per = max(1, BATCH_RAYS // samples)
        for first in range(0, len(chosen), per):
            sel = chosen[first : first + per]
            vis[sel] = self._shadow(p[sel], n[sel], samples, a, b, first)
        out = np.ones(w * h, dtype=np.float32)
        out[hit] = vis
        return out.reshape(h, w)

    def _shadow(self, p: np.ndarray, n: np.ndarray, k: int, a: int, b: int, seed: int) -> np.ndarray:
        mi, dr = self.mi, self.dr
        total = len(p) * k
        j = dr.arange(mi.UInt32, total)
        pix = j // k
        s = j % k
        si = mi.SurfaceInteraction3f()
        si.p = dr.gather(mi.Point3f, mi.Point3f(np.ascontiguousarray(p.T)), pix)
        si.n = dr.gather(mi.Normal3f, mi.Normal3f(np.ascontiguousarray(n.T)), pix)
        si.time = dr.zeros(mi.Float, total)
        rng = mi.PCG32(size=total, initstate=mi.UInt64(j) + seed * k)
        x = ((mi.Float(s % a) + rng.next_float32()) / a - 0.5) * self.size[0]
        y = ((mi.Float(s // a) + rng.next_float32()) / b - 0.5) * self.size[1]
        u, v = mi.Vector3f(*self.u.tolist()), mi.Vector3f(*self.v.tolist())
        target = mi.Vector3f(*np.asarray(self.center, dtype=float).tolist()) + x * u + y * v
        ray = si.spawn_ray(-dr.normalize(target)) if self.sun else si.spawn_ray_to(mi.Point3f(target))
        blocked = self.scene.ray_test(ray, coherent=False)
        hits = np.asarray(blocked.numpy(), dtype=np.float32).reshape(len(p), k)
        return 1.0 - hits.mean(axis=1)


def mitsuba_at(error: float, points: list[Point]) -> tuple[float, str]:
    """Mitsuba's time at ``error`` and its mark: interpolated log-log between
    its sample counts; where its fewest samples already do at least as
    well, their time (it cannot take less), marked †; * where it
    extrapolates below its most samples' error."""
    fewest = min(points, key=lambda p: p.seconds)
    if error >= fewest.error:
        return fewest.seconds, "†"
    t, outside = mitsuba_seconds_at(error, points)
    return t, "*" if outside else ""


def timed(fn: Any) -> tuple[float, Any]:
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


class Ref:
    """Visibility with the reference's G-buffer, for compare_images."""

    def __init__(self, base: Any, visibility: np.ndarray) -> None:
        self.visibility = visibility
        self.mask, self.depth, self.position, self.mesh_id = base.mask, base.depth, base.position, base.mesh_id


def describe(img: Any) -> str:
    c = img.method
    parts = [c.name]
    if getattr(c, "samples", None) and c.name in ("exact", "bitmask"):
        parts.append(f"{c.samples} samples")
    occ = getattr(c, "occluder_resolution", None)
    if occ is not None:
        parts.append(f"maps {occ[0]}×{occ[1]}")
    return ", ".join(parts)


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
        scene, light, cam = EYE_SCENES[name](res)
        ref = render_visibility(scene, light, cam, samples=args.reference_samples, seed=1)
        job = MitsubaJob(scene, light, cam)
        for k in MITSUBA_SAMPLES:
            job.run(k)  # compile the kernels
        for _, m in CALLS:
            ss.render(scene, light, cam, method=m)
        times: dict[str, list[float]] = {}
        outs: dict[str, Any] = {}
        # One job of each renderer after the other, alternating which goes
        # first, so that neither always runs in the other's wake (Dr.Jit's
        # and rayon's worker threads wind down after a call).
        jobs: list[tuple[str, Any]] = [(f"mitsuba {k}", lambda k=k, job=job: job.run(k)) for k in MITSUBA_SAMPLES] + [
            (label, lambda m=m, s=scene, li=light, c=cam: ss.render(s, li, c, method=m)) for label, m in CALLS
        ]
        for r in range(args.repeats):
            ordered = jobs if r % 2 == 0 else jobs[::-1]
            for label, fn in ordered:
                t, out = timed(fn)
                times.setdefault(label, []).append(t)
                outs[label] = out
        points: list[Point] = []
        for k in MITSUBA_SAMPLES:
            c = compare_images(Ref(ref, outs[f"mitsuba {k}"]), ref)
            points.append(Point(name, "mitsuba", f"{k} samples", float(np.median(times[f"mitsuba {k}"])), c.mean_abs))
        rows = []
        for label, _ in CALLS:
            img = outs[label]
            c = compare_images(img, ref)
            sec = float(np.median(times[label]))
            at, mark = mitsuba_at(max(c.mean_abs, 1e-6), points)
            rows.append((label, describe(img), sec, c.mean_abs, c.matched_fraction, at, mark))
        report.line(f"## {name}")
        report.line()
        report.line(
            f"{type(light).__name__}; {ref.mask.mean():.0%} of the pixels see a surface; reference "
            f"{args.reference_samples} samples."
        )
        report.line()
        report.line("| renderer | setting | time (ms) | error | Mitsuba at equal error (ms) | Mitsuba time / time |")
        report.line("|---|---|---|---|---|---|")
        for pt in points:
            report.line(f"| Mitsuba | {pt.setting} | {pt.seconds * 1e3:.0f} | {pt.error:.4f} | | |")
        for label, desc, sec, err, _matched, at, mark in rows:
            report.line(
                f"| softshadow {label} | {desc} | {sec * 1e3:.0f} | {err:.4f} | {at * 1e3:.0f}{mark} | "
                f"{at / sec:.2f}{mark} |"
            )
        report.line()
        within = [r for r in rows if r[3] <= BAR_ERROR]
        if within:
            best = min(within, key=lambda r: r[2])
            mark = best[6]
            summary.append(
                f"| {name} | {best[0]} | {best[2] * 1e3:.0f} | {best[3]:.4f} | {best[5] * 1e3:.0f}{mark} | "
                f"{best[5] / best[2]:.1f}{mark} |"
            )
        else:
            summary.append(f"| {name} | none within {BAR_ERROR} | | | | |")
    table = [
        f"| scene ({res[0]}×{res[1]}) | fastest call with error ≤ {BAR_ERROR} | time (ms) | error | "
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
    text = README.read_text()
    if START in text and END in text:
        head, rest = text.split(START, 1)
        _, tail = rest.split(END, 1)
        README.write_text(head + START + "\n" + "\n".join(table) + "\n" + END + tail)


if __name__ == "__main__":
    main()
