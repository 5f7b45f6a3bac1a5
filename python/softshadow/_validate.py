"""Argument checks shared by the public functions.

Each check raises TypeError (wrong kind of value) or ValueError (wrong value)
with a message that starts with the argument's name.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

# Keep in sync with MAX_TEXELS and MAX_EXTENT in src/light.rs: the core
# refuses larger maps and wider extents too.
MAX_TEXELS = 1 << 28
MAX_EXTENT = 1e6


class TooLargeError(ValueError, MemoryError):
    """A request refused before allocating because it would need too much
    memory. Both a ValueError (a bad argument) and a MemoryError."""


def vector(name: str, value: Any, n: int) -> tuple[float, ...]:
    """A finite float vector of length ``n``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: must be a sequence of {n} numbers, got {value!r}") from e
    if a.shape != (n,):
        raise ValueError(f"{name}: must have {n} components, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite, got {a.tolist()}")
    return tuple(float(x) for x in a)


def integer(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: must be an int, got {type(value).__name__}")
    return int(value)


def resolution(value: Any, name: str = "resolution") -> tuple[int, int]:
    """``int`` (square) or ``(W, H)``; returns (W, H)."""
    if isinstance(value, (tuple, list)):
        if len(value) != 2:
            raise ValueError(f"{name}: must be an int or (W, H), got {value!r}")
        w, h = (integer(name, v) for v in value)
    else:
        w = h = integer(name, value)
    if w < 1 or h < 1:
        raise ValueError(f"{name}: must be at least 1x1, got {w}x{h}")
    if w * h > MAX_TEXELS:
        raise TooLargeError(f"{name}: {w}x{h} would need {w * h * 4} bytes per map (limit {MAX_TEXELS} texels)")
    return w, h


def extent(value: Any) -> tuple[float, float]:
    """Tangent half-extents: a positive number or a pair of them."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        value = (value, value)
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"extent: must be None, a number or (tx, ty), got {value!r}") from e
    if a.shape != (2,):
        raise ValueError(f"extent: must be (tx, ty), got shape {a.shape}")
    if not (np.all(np.isfinite(a)) and np.all(a > 0)):
        raise ValueError(f"extent: must be finite and > 0, got {a.tolist()}")
    if np.any(a > MAX_EXTENT):
        raise ValueError(f"extent: tangent half-extents must be <= {MAX_EXTENT:g}, got {a.tolist()}")
    return float(a[0]), float(a[1])


def choice(name: str, value: Any, allowed: tuple[str, ...], later: tuple[str, ...] = ()) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name}: must be a str, got {type(value).__name__}")
    if value in later:
        raise ValueError(f"{name}: {value!r} is not available in this version; use one of {allowed}")
    if value not in allowed:
        raise ValueError(f"{name}: must be one of {allowed}, got {value!r}")
    return value


def depth_map(name: str, value: Any, shape: tuple[int, ...] | None = None, like: str = "receiver_depth") -> np.ndarray:
    """A 2-D float depth map as C-contiguous float32 (a view when it already is one)."""
    if not isinstance(value, np.ndarray):
        raise TypeError(f"{name}: must be a numpy array, got {type(value).__name__}")
    if value.dtype.kind != "f":
        raise TypeError(f"{name}: must have a float dtype, got {value.dtype}")
    if value.ndim != 2:
        raise ValueError(f"{name}: must be 2-D (H, W), got shape {value.shape}")
    if value.size == 0:
        raise ValueError(f"{name}: must not be empty, got shape {value.shape}")
    if shape is not None and value.shape != shape:
        raise ValueError(f"{name}: shape {value.shape} differs from {like}'s {shape}")
    if np.isnan(value).any():
        raise ValueError(f"{name}: contains NaN; use +inf where there is no surface")
    a = np.ascontiguousarray(value, dtype=np.float32)
    if not (a > 0).all():
        raise ValueError(f"{name}: depths must be > 0 (planar distance from the light) or +inf where empty")
    return a
