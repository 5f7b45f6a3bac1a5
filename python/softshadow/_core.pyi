"""The Rust core (pyo3 bindings). Use the package's public API instead:
these functions take already-validated, C-contiguous arrays.

Every function raises ValueError, its message starting with the argument's
name, when a value is refused (non-finite vertices, out-of-range indices, a
degenerate light, depths that are not > 0 or +inf, negative counts, a light
size the f32 kernels cannot resolve); softshadow.TooLargeError (a ValueError
and a MemoryError) for an absurd resolution, before allocating. Arrays of the
wrong dtype or number of dimensions raise TypeError from pyo3, which names
the argument in a note ("while processing 'occluder_depth'"); non-contiguous
arrays raise ValueError. A panic in the core (a bug) raises RuntimeError;
the module stays usable. The work runs with the GIL released.
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
    samples: int | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    occluder_resolution: tuple[int, int] | None = None,
    backend: str = "cpu",
) -> dict[str, Any]:
    """Rasterizes the receivers (and, for the map methods, the occluders) into
    light-view maps and computes the visibility. Returns a dict with
    ``visibility`` and ``receiver_depth`` ((H, W) float32), ``occluder_depth``
    and ``occluder_depth_back`` (on the occluder grid; None with one pass, or
    for methods that trace triangles), ``occluder_depth_middle`` (the peeled
    layers, a list; empty below 3 passes), ``extent``: (tx, ty) and
    ``timings``: {stage: seconds}. ``samples`` is for the sampling methods
    only, ``hierarchy`` (None: the method's default) for the occluder-map
    methods, ``precision`` ("f32", "f64", "f16", "f16-batched"; None: "f32")
    for "ssm". ``backend``: "cpu" or "gpu" (every method; no adapter raises
    GpuUnavailableError; the GPU has no hierarchy and sums in f32, and
    refuses ``hierarchy=True`` and other precisions)."""

def shadow_map_from_depth(
    occluder_depth: npt.NDArray[np.float32],
    occluder_depth_back: npt.NDArray[np.float32] | None,
    receiver_depth: npt.NDArray[np.float32],
    light_size: tuple[float, float],
    extent: tuple[float, float],
    method: str,
    samples: int | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = "cpu",
) -> dict[str, Any]:
    """Visibility from depth maps (the occluder maps may have their own
    resolution; the output has the receiver map's). Returns ``visibility`` and
    ``timings``. ``backend``: "cpu" or "gpu" (as for shadow_map_from_meshes)."""

def sample_points(
    light: Light,
    extent: tuple[float, float],
    width: int,
    height: int,
    points: npt.NDArray[np.float64],
    method: str,
    samples: int | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    occluder_depth: npt.NDArray[np.float32] | None = None,
    occluder_depth_back: npt.NDArray[np.float32] | None = None,
    occ_vertices: npt.NDArray[np.float64] | None = None,
    occ_faces: npt.NDArray[np.uint32] | None = None,
    occluder_depth_middle: list[npt.NDArray[np.float32]] | None = None,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.bool_]]:
    """Visibility at world points (N, 3), and whether each lies inside the map
    (points outside, or at or behind the light's plane, get 1 and False). The
    occluders are the occluder maps (map methods) or the mesh (``"exact"``)."""

def receiver_points(
    receiver_depth: npt.NDArray[np.float32],
    light: Light,
    extent: tuple[float, float],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]:
    """World points (M, 3) of the texels with a receiver, and their flat indices."""

class GpuUnavailableError(RuntimeError):
    """backend="gpu" was asked for and no GPU adapter can be opened (none
    present, no Vulkan driver, or SOFTSHADOW_GPU=off)."""

def gpu_available() -> bool:
    """Whether a GPU adapter opens (software ones such as lavapipe count).
    The device is opened once per process and kept."""

def gpu_info() -> dict[str, Any]:
    """The adapter backend="gpu" uses: ``name``, ``backend`` ("vulkan"),
    ``device_type`` ("discrete_gpu", "integrated_gpu", "virtual_gpu", "cpu"
    or "other"), ``driver`` and ``software`` (bool: a CPU renderer). Raises
    GpuUnavailableError when there is none."""

def _panic_for_tests(in_worker: bool) -> None:
    """Panics on purpose (in a rayon worker thread when ``in_worker``) to test
    that panics become RuntimeError. Not part of the API."""
