"""The GPU adapter ``backend="gpu"`` runs on.

The choice of backend and its dispatch are the core's (``backend=`` is
passed through): ``"cpu"`` (all cores), ``"gpu"`` (wgpu; never falls back:
no adapter raises :class:`GpuUnavailableError`) or ``"auto"`` (the GPU when a
real, non-software adapter is present and runs the call, else the CPU).
``SOFTSHADOW_GPU=off`` in the environment hides every adapter.
"""

from __future__ import annotations

from typing import Any

from . import _core

GpuUnavailableError = _core.GpuUnavailableError


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
