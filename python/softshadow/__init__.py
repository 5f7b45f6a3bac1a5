"""softshadow: soft shadows cast by rectangular area lights and the sun.

Soft shadow maps (Atty et al. 2005), their bitmask variant, ray casting,
PCSS, Smoothies and Scherzer's shadow mapping, computed by a Rust core on
all CPU cores or on a GPU through wgpu (``backend="gpu"``). Pick a method
with a typed config (``Ssm``, ``Bitmask``, ``Exact``, ``PCSS``,
``Smoothies``, ``ShadowMapping``, ``Auto``) or its name;
:func:`capabilities` lists every method's options, defaults, limits and
backends. See the README and docs/ for the conventions.

What is exported here lives in modules that say what they hold:
:mod:`.api` (the calls: ``soft_shadow_map``, ``soft_shadow_map_from_depth``,
``render``, ``gpu_available``, ``gpu_info``), :mod:`.results` (``ShadowMap``,
``Image``, ``Plan``, ``Decision``, ``ErrorEstimate``), :mod:`.lights` (``RectLight``,
``DiskLight``, ``SphereLight``, ``DirectionalLight``), :mod:`.scene` (``Scene``, ``Camera``), :mod:`.materials`
(``Material``, the colours ``Scene.from_trimesh`` reads), :mod:`.methods`
(the configs, ``capabilities``, ``limits``) and :mod:`.errors`. Built-in
scenes are in :mod:`softshadow.scenes`, files in :mod:`softshadow.io`, error
metrics in :mod:`softshadow.metrics`, Mitsuba references in
:mod:`softshadow.reference`.
"""

from . import methods

# The method configs and their parts: the core's `__all__`, made from its
# table (a new method's class needs no line here; mypy reads the stub's
# list). `methods.__all__` adds their table and limits to it.
from ._core import *  # noqa: F403
from ._core import __version__
from .api import gpu_available, gpu_info, render, soft_shadow_map, soft_shadow_map_from_depth
from .errors import GpuUnavailableError, TooLargeError
from .lights import DirectionalLight, DiskLight, RectLight, SphereLight
from .materials import Material
from .methods import *  # noqa: F403
from .results import Decision, ErrorEstimate, Image, Plan, ShadowMap
from .scene import Camera, Scene

__all__ = [
    "Camera",
    "Decision",
    "DirectionalLight",
    "DiskLight",
    "ErrorEstimate",
    "GpuUnavailableError",
    "Image",
    "Material",
    "Plan",
    "RectLight",
    "Scene",
    "ShadowMap",
    "SphereLight",
    "TooLargeError",
    "gpu_available",
    "gpu_info",
    "render",
    "soft_shadow_map",
    "soft_shadow_map_from_depth",
    "__version__",
]
__all__ += methods.__all__
