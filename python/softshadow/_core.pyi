"""The Rust core (pyo3 bindings). Use the package's public API instead:
these functions take already-validated, C-contiguous arrays.

Every function raises ValueError, its message starting with the argument's
name, when a value is refused (non-finite vertices, out-of-range indices, a
degenerate light, depths that are not > 0 or +inf, an absurd resolution).
The work runs with the GIL released.
"""

from typing import Any

import numpy as np
import numpy.typing as npt

__version__: str

#: (center, normal, up, size)
Light = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float], tuple[float, float]]

def light_frame(light: Light) -> tuple[list[float], list[float], list[float]]:
    """Validates a light and returns its frame (u, v, n) as unit vectors."""

def shadow_map_from_meshes(
    occ_vertices: npt.NDArray[np.float64],
    occ_faces: npt.NDArray[np.uint32],
    rec_vertices: npt.NDArray[np.float64],
    rec_faces: npt.NDArray[np.uint32],
    light: Light,
    width: int,
    height: int,
    extent: tuple[float, float] | None,
    passes: int,
    method: str,
) -> dict[str, Any]:
    """Rasterizes occluders and receivers into light-view maps and computes the
    visibility. Returns a dict with ``visibility``, ``receiver_depth``,
    ``occluder_depth``, ``occluder_depth_back`` (None with one pass): (H, W)
    float32 arrays; ``extent``: (tx, ty); ``timings``: {stage: seconds}."""

def shadow_map_from_depth(
    occluder_depth: npt.NDArray[np.float32],
    occluder_depth_back: npt.NDArray[np.float32] | None,
    receiver_depth: npt.NDArray[np.float32],
    light_size: tuple[float, float],
    extent: tuple[float, float],
    method: str,
) -> dict[str, Any]:
    """Visibility from depth maps. Returns ``visibility`` and ``timings``."""

def sample_points(
    occluder_depth: npt.NDArray[np.float32],
    occluder_depth_back: npt.NDArray[np.float32] | None,
    light: Light,
    extent: tuple[float, float],
    points: npt.NDArray[np.float64],
    method: str,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_]]:
    """Visibility at world points (N, 3), and whether each lies inside the map
    (points outside, or at or behind the light's plane, get 1 and False)."""

def receiver_points(
    receiver_depth: npt.NDArray[np.float32],
    light: Light,
    extent: tuple[float, float],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]:
    """World points (M, 3) of the texels with a receiver, and their flat indices."""
