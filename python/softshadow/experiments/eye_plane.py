"""The accuracy-time plane in eye view: every method family against
Mitsuba's whole eye-view job, on one scene, timed in one run.

For a scene of :data:`softshadow.scenes.eye_view.EYE_SCENES`:

* the reference: :func:`softshadow.reference.render_visibility` with many
  stratified light samples a pixel;
* Mitsuba's job (:class:`softshadow.reference.eye_job.MitsubaEyeJob`) at
  :data:`MITSUBA_SAMPLES` samples a pixel, its time and error;
* every call of :data:`CALLS`: ``softshadow.render`` end to end from the
  meshes, its time, its error and Mitsuba's time at that error.

The error is the mean |V - V_ref| over the pixels the reference shadows,
where both renderers see the same mesh at the same place
(:func:`softshadow.metrics.compare_images`'s ``shadow_error``; the tables
keep the mean over all those pixels, lit ones included, beside it).
Each round times every call and every Mitsuba sample count once, in an
order reversed every other round, so both sides of a ratio see the same
load, and each after a pause of :data:`SETTLE_S` so that neither runs in
the other's wake (Dr.Jit's and rayon's worker threads wind down after a
call: without the pause, softshadow's stages timed right after a Mitsuba
job read up to twice their time, ``benchmarks/bench_scale.py``). Used by ``benchmarks/bench_eye.py``
(tables, the README's eye table) and the study (plots).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import (
    PCF,
    PCSS,
    Bitmask,
    Exact,
    EyeSpaceBlur,
    ShadowMapping,
    SlopeScaleBias,
    Smoothies,
    render,
)
from ..metrics import compare_images
from ..scenes.eye_view import EYE_SCENES
from .points import Point, mitsuba_seconds_at

#: 1 and 4 besides 16, 64 and 256: Mitsuba's error at low counts is small on
#: this metric (most pixels are fully lit or in umbra, which one sample gets
#: right), and extrapolating below 16 would undercut its real floor, the
#: first hits plus one ray a pixel.
MITSUBA_SAMPLES = (1, 4, 16, 64, 256)
#: (family, label, method): the family groups the study's plot.
CALLS: list[tuple[str, str, Any]] = [
    ("auto", "default (probe 16, exact 256)", "auto"),
    ("ssm", "ssm", "ssm"),
    ("bitmask", "bitmask 64", Bitmask(samples=64)),
    ("bitmask", "bitmask 256", Bitmask(samples=256)),
    ("exact", "exact 16", Exact(samples=16)),
    ("exact", "exact 64", Exact(samples=64)),
    # Exact's masks alone at 256 samples, and four times the samples
    # behind the default's probe.
    ("exact", "exact 256, masks", Exact(samples=256, engine="masks")),
    ("exact", "probe 16, exact 1024", Exact(samples=1024, probe=16)),
    ("pcss", "pcss", PCSS()),
    ("pcss", "pcss, 8 taps", PCSS(max_taps=8)),
    ("smoothies", "smoothies", Smoothies()),
    ("shadow map", "shadow map", ShadowMapping()),
    ("shadow map, PCF", "shadow map, PCF 3", ShadowMapping(filter=PCF(size=3), bias=SlopeScaleBias(slope=4))),
    ("shadow map, blur", "shadow map, blur 4", ShadowMapping(blur=EyeSpaceBlur(iterations=4))),
]


@dataclass
class EyeRow:
    """One call on one scene: its time, error and Mitsuba's time at that error."""

    family: str
    label: str
    setting: str
    seconds: float
    #: Mean |V - V_ref| over the pixels the reference shadows (the headline,
    #: docs/accuracy.md), and over every matched pixel (lit ones too).
    error: float
    error_all: float
    matched: float
    #: Mitsuba's time at this error, and its mark ("†": its fewest samples
    #: already do as well; "*": extrapolated; "": interpolated).
    mitsuba_seconds: float
    mark: str


@dataclass
class EyePlane:
    scene: str
    light: str
    #: Fraction of the pixels that see a surface.
    coverage: float
    reference_samples: int
    mitsuba: list[Point]
    rows: list[EyeRow]

    def points(self) -> list[Point]:
        """Every setting as a study :class:`Point` (family as the method)."""
        return self.mitsuba + [Point(self.scene, r.family, r.label, r.seconds, r.error) for r in self.rows]


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


class _Ref:
    """Visibility with the reference's G-buffer, for compare_images."""

    def __init__(self, base: Any, visibility: np.ndarray) -> None:
        self.visibility = visibility
        self.mask, self.depth, self.position, self.mesh_id = base.mask, base.depth, base.position, base.mesh_id


def describe(img: Any) -> str:
    """The resolved config's main settings, for the tables."""
    c = img.method
    parts = [c.name]
    if getattr(c, "samples", None) and c.name in ("exact", "bitmask"):
        parts.append(f"{c.samples} samples")
    if getattr(c, "probe", None):
        parts.append(f"probe {c.probe}")
    if getattr(c, "engine", None):
        parts.append(str(c.engine))
    occ = getattr(c, "occluder_resolution", None)
    if occ is not None:
        parts.append(f"maps {occ[0]}×{occ[1]}")
    return ", ".join(parts)


SETTLE_S = 0.05
"""Seconds each timed call waits first for the other renderer's threads."""


def _timed(fn: Any) -> tuple[float, Any]:
    time.sleep(SETTLE_S)
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def eye_plane(
    name: str,
    resolution: tuple[int, int],
    *,
    repeats: int,
    reference_samples: int,
    calls: list[tuple[str, str, Any]] | None = None,
    built: tuple[Any, Any, Any] | None = None,
    reference: Any = None,
    mitsuba_samples: tuple[int, ...] = MITSUBA_SAMPLES,
) -> EyePlane:
    """Measures every call of ``calls`` (default :data:`CALLS`) and Mitsuba's
    job (at ``mitsuba_samples`` a pixel) on the eye scene ``name`` at
    ``resolution`` (or on ``built``, a (scene, light, camera) triple, against
    ``reference``); times are medians of ``repeats`` rounds after a warm-up
    (which compiles Dr.Jit's kernels and prepares the scene for the calls
    after it, as Mitsuba's scene is loaded once)."""
    from ..reference import render_visibility
    from ..reference.eye_job import MitsubaEyeJob

    calls = CALLS if calls is None else calls
    scene, light, cam = EYE_SCENES[name](resolution) if built is None else built
    ref = render_visibility(scene, light, cam, samples=reference_samples, seed=1) if reference is None else reference
    job = MitsubaEyeJob(scene, light, cam)
    jobs: list[tuple[str, Any]] = [(f"mitsuba {k}", lambda k=k: job.run(k)) for k in mitsuba_samples]
    jobs += [(label, lambda m=m: render(scene, light, cam, method=m)) for _, label, m in calls]
    for _, fn in jobs:
        fn()  # warm-up
    times: dict[str, list[float]] = {}
    outs: dict[str, Any] = {}
    for r in range(repeats):
        for label, fn in jobs if r % 2 == 0 else jobs[::-1]:
            t, out = _timed(fn)
            times.setdefault(label, []).append(t)
            outs[label] = out
    mitsuba = [
        Point(
            name,
            "mitsuba",
            f"{k} samples",
            float(np.median(times[f"mitsuba {k}"])),
            compare_images(_Ref(ref, outs[f"mitsuba {k}"]), ref).shadow_error,
        )
        for k in mitsuba_samples
    ]
    rows = []
    for family, label, _ in calls:
        img = outs[label]
        c = compare_images(img, ref)
        at, mark = mitsuba_at(max(c.shadow_error, 1e-6), mitsuba)
        sec = float(np.median(times[label]))
        rows.append(EyeRow(family, label, describe(img), sec, c.shadow_error, c.mean_abs, c.matched_fraction, at, mark))
    return EyePlane(name, type(light).__name__, float(ref.mask.mean()), reference_samples, mitsuba, rows)


def markdown_eye_plane(plane: EyePlane) -> list[str]:
    """The scene's table: Mitsuba's rows, then every call's."""
    lines = [
        "| renderer | setting | time (ms) | error over shadowed pixels | over all pixels "
        "| Mitsuba at equal error (ms) | Mitsuba time / time |",
        "|---|---|---|---|---|---|---|",
    ]
    for pt in plane.mitsuba:
        lines.append(f"| Mitsuba | {pt.setting} | {pt.seconds * 1e3:.0f} | {pt.error:.4f} | | | |")
    for r in plane.rows:
        lines.append(
            f"| softshadow {r.label} | {r.setting} | {r.seconds * 1e3:.0f} | {r.error:.4f} | {r.error_all:.4f} | "
            f"{r.mitsuba_seconds * 1e3:.0f}{r.mark} | {r.mitsuba_seconds / r.seconds:.2f}{r.mark} |"
        )
    return lines


def best_within(plane: EyePlane, error: float) -> EyeRow | None:
    """The fastest call with error at most ``error``."""
    within = [r for r in plane.rows if r.error <= error]
    return min(within, key=lambda r: r.seconds) if within else None


def markdown_eye_summary(planes: list[EyePlane]) -> list[str]:
    """Per family (rows) and scene (columns): its most accurate call's error
    and time, and Mitsuba's time at that error over that time."""
    families = list(dict.fromkeys(r.family for p in planes for r in p.rows))
    lines = [
        "| family | " + " | ".join(f"{p.scene}: error, ms (Mitsuba ×)" for p in planes) + " |",
        "|---|" + "---|" * len(planes),
    ]
    for fam in families:
        cells = []
        for p in planes:
            rows = [r for r in p.rows if r.family == fam]
            if not rows:
                cells.append("-")
                continue
            r = min(rows, key=lambda r: r.error)
            cells.append(f"{r.error:.4f}, {r.seconds * 1e3:.0f} ({r.mitsuba_seconds / r.seconds:.1f}{r.mark})")
        lines.append(f"| {fam} | " + " | ".join(cells) + " |")
    return lines
