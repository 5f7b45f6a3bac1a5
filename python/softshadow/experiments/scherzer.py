"""Scherzer 2005's experiments (practical shadow mapping for large scenes)
and Chan & Durand 2003's smoothie width, measured in eye view.

* :func:`bias_errors`: each bias method of ``ShadowMapping`` on every eye
  scene against the exact hard shadow (``exact`` with the light shrunk to
  its centre, or the sun to its direction): *acne* is the fraction of
  visible pixels lit there and shadowed by the map, *peter-panning* the
  fraction shadowed there and lit by the map (Scherzer §3).
* :func:`aliasing_errors`: uniform, focused and LiSPSM maps against map
  resolution on ``large_city`` (a large city seen from near the ground under
  the sun): the fraction of visible pixels misclassified against the exact
  hard shadow, and the render's time (Scherzer §4-§5).
* :func:`soft_curves`: the eye-space blur's iterations (Scherzer §6) and
  Smoothies' width (Chan & Durand §3) against the mean |V - V_exact| under
  the scene's own soft light (256-sample ``exact``), and time.

Shared by ``benchmarks/bench_shadow_mapping.py`` (tables) and the study
(tables and plots). Times are medians of ``repeats``, end to end from the
meshes.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from .. import (
    BackFaces,
    ConstantBias,
    DirectionalLight,
    Exact,
    EyeSpaceBlur,
    LinearDepthBias,
    LiSPSM,
    MidpointBias,
    RectLight,
    ShadowMapping,
    SlopeScaleBias,
    Smoothies,
    render,
)
from ..scenes.eye_view import EYE_SCENES, large_city

BIASES: list[tuple[str, Any]] = [
    ("none (ConstantBias(constant=0))", ConstantBias(constant=0)),
    ("ConstantBias(constant=1000)", ConstantBias(constant=1000)),
    ("SlopeScaleBias() (default)", SlopeScaleBias()),
    ("LinearDepthBias()", LinearDepthBias()),
    ("BackFaces()", BackFaces()),
    ("MidpointBias()", MidpointBias()),
]
MAPS: list[tuple[str, dict[str, Any]]] = [
    ("unfocused", dict(focus=False)),
    ("focused", dict(focus=True)),
    ("focused LiSPSM (middle vector)", dict(warp=LiSPSM())),
    ("focused LiSPSM (camera axis)", dict(warp=LiSPSM(vector="camera"))),
]
RESOLUTIONS = (512, 1024, 2048, 4096)
BLUR_ITERATIONS = (0, 1, 2, 4, 8, 16)
SMOOTHIE_WIDTHS = (0.25, 0.5, 1.0, 2.0, 4.0)
#: (error, seconds) per setting.
Curve = list[tuple[float, float]]


def hard(light: Any) -> Any:
    """The light shrunk to its centre (a rectangle) or its direction (the sun)."""
    if isinstance(light, RectLight):
        return RectLight(light.center, light.normal, light.up, size=(0.0, 0.0))
    return DirectionalLight(light.direction, light.up, angular_size=(0.0, 0.0))


def timed(fn: Any, repeats: int) -> tuple[float, Any]:
    """The median time of ``repeats`` calls and the last call's output."""
    out, times = None, []
    for _ in range(max(1, repeats)):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def bias_errors(resolution: tuple[int, int]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per bias label, per eye scene: (acne, peter-panning) with 2048² maps."""
    cases = []
    for name, make in EYE_SCENES.items():
        scene, light, cam = make(resolution)
        h = hard(light)
        cases.append((name, scene, h, cam, render(scene, h, cam, method="exact")))
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for label, bias in BIASES:
        out[label] = {}
        for name, scene, h, cam, ref in cases:
            img = render(scene, h, cam, method=ShadowMapping(bias=bias))
            r, v, m = ref.visibility > 0.5, img.visibility > 0.5, ref.mask
            out[label][name] = (float(np.mean((r & ~v)[m])), float(np.mean((~r & v)[m])))
    return out


def aliasing_errors(
    resolution: tuple[int, int], repeats: int, resolutions: tuple[int, ...] = RESOLUTIONS
) -> dict[str, Curve]:
    """Per map kind: (misclassified fraction, seconds) at each map resolution."""
    scene, sun, cam = large_city(resolution)
    h = hard(sun)
    ref = render(scene, h, cam, method="exact")
    out: dict[str, Curve] = {}
    for label, kw in MAPS:
        out[label] = []
        for r in resolutions:
            sec, img = timed(
                lambda kw=kw, r=r: render(scene, h, cam, method=ShadowMapping(resolution=r, **kw)), repeats
            )
            wrong = float(np.mean(((img.visibility > 0.5) != (ref.visibility > 0.5))[ref.mask]))
            out[label].append((wrong, sec))
    return out


def soft_curves(
    resolution: tuple[int, int],
    repeats: int,
    iterations: tuple[int, ...] = BLUR_ITERATIONS,
    widths: tuple[float, ...] = SMOOTHIE_WIDTHS,
) -> tuple[dict[str, Curve], dict[str, Curve]]:
    """Per eye scene: the blur's (error, seconds) at each iteration count
    (0: no blur) and Smoothies' at each width."""
    blur: dict[str, Curve] = {}
    width: dict[str, Curve] = {}
    for name, make in EYE_SCENES.items():
        s, li, c = make(resolution)
        ref = render(s, li, c, method=Exact(samples=256))

        def err(img: Any, ref: Any = ref) -> float:
            return float(np.abs(img.visibility - ref.visibility)[ref.mask].mean())

        blur[name] = []
        for it in iterations:
            b = EyeSpaceBlur(iterations=it) if it else None
            sec, img = timed(lambda b=b, s=s, li=li, c=c: render(s, li, c, method=ShadowMapping(blur=b)), repeats)
            blur[name].append((err(img), sec))
        width[name] = []
        for w in widths:
            sec, img = timed(lambda w=w, s=s, li=li, c=c: render(s, li, c, method=Smoothies(width=w)), repeats)
            width[name].append((err(img), sec))
    return blur, width
