"""softshadow: soft shadows cast by rectangular area lights and the sun.

Soft shadow maps (Atty et al. 2005), their bitmask variant and exact ray
casting, computed by a Rust core on all CPU cores or on a GPU through wgpu
(``backend="gpu"``). Pick a method with a typed config (``Ssm``,
``Bitmask``, ``Exact``, ``Auto``, ``ShadowMapping``) or its name; :func:`capabilities` lists
every method's options, defaults, limits and backends. See the README and
docs/ for the conventions.
"""

from ._core import __version__
from .api import gpu_available, gpu_info, render, soft_shadow_map, soft_shadow_map_from_depth
from .errors import GpuUnavailableError, TooLargeError
from .lights import DirectionalLight, RectLight
from .methods import (
    PCF,
    PCSS,
    Auto,
    BackFaces,
    Bitmask,
    ConstantBias,
    Exact,
    EyeSpaceBlur,
    LinearDepthBias,
    LiSPSM,
    MethodConfig,
    MethodInfo,
    MidpointBias,
    OptionInfo,
    ShadowMapping,
    SlopeScaleBias,
    Smoothies,
    Ssm,
    capabilities,
    limits,
)
from .results import Decision, Image, Plan, ShadowMap
from .scene import Camera, Scene

__all__ = [
    "SlopeScaleBias",
    "Smoothies",
    "ShadowMapping",
    "MidpointBias",
    "LinearDepthBias",
    "LiSPSM",
    "EyeSpaceBlur",
    "ConstantBias",
    "BackFaces",
    "PCF",
    "Auto",
    "Bitmask",
    "Camera",
    "Decision",
    "DirectionalLight",
    "Exact",
    "GpuUnavailableError",
    "Image",
    "MethodConfig",
    "MethodInfo",
    "OptionInfo",
    "PCSS",
    "Plan",
    "RectLight",
    "Scene",
    "ShadowMap",
    "Ssm",
    "TooLargeError",
    "capabilities",
    "gpu_available",
    "gpu_info",
    "limits",
    "render",
    "soft_shadow_map",
    "soft_shadow_map_from_depth",
    "__version__",
]
