"""softshadow: soft shadows cast by rectangular area lights.

Soft shadow maps (Atty et al. 2005) computed by a Rust core on all CPU cores.
See the README for the conventions.
"""

from ._core import __version__
from ._validate import TooLargeError
from .light import RectLight
from .scene import Scene
from .shadow_map import ShadowMap, soft_shadow_map, soft_shadow_map_from_depth

__all__ = [
    "RectLight",
    "Scene",
    "ShadowMap",
    "TooLargeError",
    "soft_shadow_map",
    "soft_shadow_map_from_depth",
    "__version__",
]
