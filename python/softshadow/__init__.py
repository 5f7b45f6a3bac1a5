"""softshadow: soft shadows cast by rectangular area lights.

Soft shadow maps (Atty et al. 2005) computed by a Rust core on all CPU cores,
or on a GPU through wgpu (``backend="gpu"``).
See the README for the conventions.
"""

from ._core import __version__
from ._validate import TooLargeError
from .backend import GpuUnavailableError, gpu_available, gpu_info
from .light import RectLight
from .scene import Scene
from .shadow_map import ShadowMap, soft_shadow_map, soft_shadow_map_from_depth

__all__ = [
    "GpuUnavailableError",
    "RectLight",
    "Scene",
    "ShadowMap",
    "TooLargeError",
    "soft_shadow_map",
    "soft_shadow_map_from_depth",
    "gpu_available",
    "gpu_info",
    "__version__",
]
