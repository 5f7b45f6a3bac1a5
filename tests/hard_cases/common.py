"""Shared parameters of the hard cases: every method and backend the package
offers joins every test through these lists (a new backend or method is
tested by adding it to the core's capabilities table, nothing here)."""

from __future__ import annotations

import numpy as np

import softshadow as ss

__all__ = [
    "BACKENDS",
    "MAP_METHODS",
    "METHODS",
    "SAMPLES",
    "assert_visibility",
    "has_option",
    "options",
    "runs_on",
    "samples_points",
]

_CAPS = ss.capabilities()
# Every light-view method that runs on every backend of this build ("auto"
# is a rule that resolves to one of them; a method that reads a camera has
# the eye view only). Its GPU twin is what lets a method join these lists; a
# CPU-only method has its hard cases in
# tests/methods/test_shadow_mapping.py until its GPU twin joins these lists.
_ALL = set(_CAPS["ssm"].backends)
METHODS = tuple(
    name for name in _CAPS if name != "auto" and "camera" not in _CAPS[name].reads and set(_CAPS[name].backends) == _ALL
)
# Every backend of this build that runs some method.
BACKENDS = tuple(dict.fromkeys(b for name in METHODS for b in _CAPS[name].backends))
TRACING_METHODS = tuple(name for name in METHODS if "occluder_triangles" in _CAPS[name].reads)
# Methods that read depth maps (so work from soft_shadow_map_from_depth).
MAP_METHODS = tuple(m for m in METHODS if m not in TRACING_METHODS)
# Samples for the sampling methods in these tests: enough to resolve the
# numbers asserted, few enough to keep the suite fast.
SAMPLES = {"bitmask": 256, "exact": 256}


def runs_on(method: str, backend: str) -> bool:
    """Whether the table says ``backend`` runs ``method``."""
    return backend in _CAPS[method].backends


def samples_points(method: str) -> bool:
    """Whether ``ShadowMap.sample`` shades a map of ``method`` at points
    (smoothies read the occluder mesh besides its maps: refused by name)."""
    return not {"occluder_layers", "occluder_triangles"} <= set(_CAPS[method].reads)


def has_option(method: str, option: str) -> bool:
    return option in _CAPS[method].options or (option == "passes" and method == "exact")


def options(method: str, backend: str, passes: int | None = None) -> dict:
    """Keyword arguments for method and backend (and ``passes`` where the
    method has occluder layers to peel: smoothies read the front one only)."""
    kw: dict = {"method": method, "backend": backend}
    if method in SAMPLES:
        kw["samples"] = SAMPLES[method]
    if passes is not None and has_option(method, "passes"):
        kw["passes"] = passes
    return kw


def assert_visibility(v: np.ndarray) -> None:
    """Every visibility map: float32, finite, in [0, 1]."""
    assert v.dtype == np.float32
    assert np.isfinite(v).all(), "non-finite visibility"
    assert v.min() >= 0.0 and v.max() <= 1.0, (float(v.min()), float(v.max()))
