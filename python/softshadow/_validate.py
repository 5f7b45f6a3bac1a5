"""Type conversions shared by the public functions.

They check only types and shapes (TypeError for a wrong kind of value,
ValueError for a wrong shape, each naming the argument) and convert to what
``_core`` borrows; every check of a value (ranges, finiteness, limits) is the
core's and happens there, once.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np


def vector(name: str, value: Any, n: int) -> tuple[float, ...]:
    """A float vector of length ``n`` (the core checks that it is finite)."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: must be a sequence of {n} numbers, got {value!r}") from e
    if a.shape != (n,):
        raise ValueError(f"{name}: must have {n} components, got shape {a.shape}")
    return tuple(float(x) for x in a)


def pair(name: str, value: Any) -> tuple[float, float]:
    """A number (both components) or a pair of numbers."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value), float(value)
    x, y = vector(name, value, 2)
    return x, y


def depth_map(name: str, value: Any) -> np.ndarray:
    """A 2-D float depth map as C-contiguous float32 (a view when it already
    is one); the core checks its depths."""
    if not isinstance(value, np.ndarray):
        raise TypeError(f"{name}: must be a numpy array, got {type(value).__name__}")
    if value.dtype.kind != "f":
        raise TypeError(f"{name}: must have a float dtype, got {value.dtype}")
    if value.ndim != 2:
        raise ValueError(f"{name}: must be 2-D (H, W), got shape {value.shape}")
    if value.size == 0:
        raise ValueError(f"{name}: must not be empty, got shape {value.shape}")
    return np.ascontiguousarray(value, dtype=np.float32)


def color(value: Any) -> Any:
    """NumPy arrays and scalars, at any depth of lists and tuples, as plain
    Python numbers and lists (what the core's conversion reads); anything
    else unchanged (the core names its type)."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [color(v) for v in value]
    return value
