"""Validation of the reference functions' inputs, and the light's frame.

Everything here is NumPy alone and runs before Mitsuba is imported, so bad
arguments fail fast and without the ``reference`` extra.

A rectangular light has a ``center`` c, a ``normal`` pointing from the light
into the scene, an ``up`` vector and a ``size`` (sx, sy). Its frame is
``n = normalize(normal)``, ``v = normalize(up - (up.n) n)``, ``u = n x v``;
``sx`` is the full width along u and ``sy`` the full height along v.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np

#: ``(c, u, v, n, sx, sy)``: a light's center and orthonormal frame (float64
#: 3-vectors) and its full width along u and height along v.
LightFrame: TypeAlias = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float]


def _vector3(value: Any, name: str) -> np.ndarray:
    """Convert to a finite float64 3-vector or raise naming ``name``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a sequence of 3 numbers") from exc
    if array.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {array.tolist()}")
    return array


def _light_frame(light: Any) -> LightFrame:
    """Return ``(c, u, v, n, sx, sy)`` in float64 for a rectangular light.

    Independent of the core's frame code on purpose (see
    ``visibility._texel_world_points``).

    ``light`` is any object with ``center``, ``normal``, ``up`` (3-sequences)
    and ``size`` (2-sequence) attributes.
    """
    for attribute in ("center", "normal", "up", "size"):
        if not hasattr(light, attribute):
            raise TypeError(f"light has no attribute {attribute!r}")
    center = _vector3(light.center, "light.center")
    normal = _vector3(light.normal, "light.normal")
    up = _vector3(light.up, "light.up")
    try:
        size = np.asarray(light.size, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError("light.size must be a sequence of 2 numbers") from exc
    if size.shape != (2,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise ValueError(f"light.size must be 2 positive finite numbers, got {size}")
    length = np.linalg.norm(normal)
    if length == 0.0:
        raise ValueError("light.normal must be non-zero")
    n = normal / length
    v = up - np.dot(up, n) * n
    v_length = np.linalg.norm(v)
    if v_length <= 1e-9 * max(float(np.linalg.norm(up)), 1.0):
        raise ValueError("light.up must not be parallel to light.normal")
    v /= v_length
    u = np.cross(n, v)
    return center, u, v, n, float(size[0]), float(size[1])


def _points(points: Any) -> np.ndarray:
    """Validate query points as a finite (N, 3) float64 array."""
    try:
        array = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError("points must be an (N, 3) array of numbers") from exc
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError("points must be finite (found NaN or inf)")
    return array


def _positive_int(value: Any, name: str) -> int:
    """Validate a positive integer (bools are rejected)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an int, got {type(value).__name__}")
    if value <= 0:
        raise ValueError(f"{name} must be positive, got {value}")
    return int(value)


def _seed(value: Any) -> int:
    """Validate an RNG seed (a non-negative int)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"seed must be an int, got {type(value).__name__}")
    if value < 0:
        raise ValueError(f"seed must be non-negative, got {value}")
    return int(value)


def _mesh_arrays(meshes: Any, name: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Normalise meshes to a list of (float32 (n,3) vertices, uint32 (m,3) faces).

    Each mesh is a ``(vertices, faces)`` pair or an object with ``.vertices``
    and ``.faces`` (e.g. ``trimesh.Trimesh``). Meshes without faces are
    dropped, since they cannot block anything.
    """
    if isinstance(meshes, (str, bytes)) or not isinstance(meshes, Sequence):
        raise TypeError(f"{name} must be a list of meshes")
    result = []
    for index, mesh in enumerate(meshes):
        label = f"{name}[{index}]"
        if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
            vertices, faces = mesh.vertices, mesh.faces
        elif isinstance(mesh, (tuple, list)) and len(mesh) == 2:
            vertices, faces = mesh
        else:
            raise TypeError(f"{label} must be a (vertices, faces) pair or have .vertices and .faces")
        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"{label} vertices must be (n, 3), got {vertices.shape}")
        if not np.all(np.isfinite(vertices)):
            raise ValueError(f"{label} vertices must be finite")
        if faces.size == 0:
            continue
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"{label} faces must be (m, 3), got {faces.shape}")
        if not np.issubdtype(faces.dtype, np.integer):
            raise TypeError(f"{label} faces must be integers, got {faces.dtype}")
        if faces.min() < 0 or faces.max() >= len(vertices):
            raise ValueError(f"{label} faces index vertices out of range")
        result.append(
            (
                np.ascontiguousarray(vertices, dtype=np.float32),
                np.ascontiguousarray(faces, dtype=np.uint32),
            )
        )
    return result
