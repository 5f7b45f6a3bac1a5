"""Which backend runs a shadow map: the CPU (all cores) or the GPU (wgpu).

``backend="gpu"`` runs the mesh pipeline on the GPU and never falls back:
without an adapter it raises :class:`GpuUnavailableError`, and a method
without a GPU kernel would raise ValueError (every method has one in this
version). ``backend="auto"`` takes the GPU when a real (non-software) adapter
is present and the method runs there, else the CPU.
``SOFTSHADOW_GPU=off`` in the environment hides every adapter.
"""

from __future__ import annotations

from typing import Any

from . import _core
from . import _validate as check

GpuUnavailableError = _core.GpuUnavailableError

BACKENDS = ("cpu", "gpu", "auto")
# Methods with a GPU kernel; keep in sync with method_source in src/gpu/gather.rs.
GPU_METHODS = ("ssm", "bitmask", "exact")


def gpu_available() -> bool:
    """Whether ``backend="gpu"`` can run here: a GPU adapter opens (a software
    one such as Mesa's lavapipe counts; see :func:`gpu_info`)."""
    return bool(_core.gpu_available())


def gpu_info() -> dict[str, Any]:
    """The adapter ``backend="gpu"`` uses: ``name``, ``backend`` (the graphics
    API, "vulkan"), ``device_type`` ("discrete_gpu", "integrated_gpu",
    "virtual_gpu", "cpu" or "other"), ``driver`` and ``software`` (True for a
    CPU renderer like lavapipe, which ``backend="auto"`` does not pick).
    Raises GpuUnavailableError when there is none."""
    return dict(_core.gpu_info())


def _real_gpu() -> bool:
    return gpu_available() and not gpu_info()["software"]


def resolve(backend: Any, method: str, gpu_methods: tuple[str, ...] = GPU_METHODS) -> str:
    """"cpu" or "gpu" for a validated ``method``; ``gpu_methods`` are the
    methods the entry point can run on the GPU."""
    backend = check.choice("backend", backend, BACKENDS)
    if backend == "auto":
        return "gpu" if method in gpu_methods and _real_gpu() else "cpu"
    if backend == "gpu" and method not in gpu_methods:
        raise ValueError(
            f"method: {method!r} is not implemented on the GPU backend yet (GPU methods: {gpu_methods}); "
            'use backend="cpu"'
        )
    return backend
