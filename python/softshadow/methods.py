"""The methods a user picks, as typed configs, and the core's table of them.

``Ssm``, ``Bitmask``, ``Exact``, ``PCSS``, ``Smoothies``, ``ShadowMapping``
(with its bias, filter and warp options: ``ConstantBias``, ``SlopeScaleBias``,
``LinearDepthBias``, ``BackFaces``, ``MidpointBias``, ``PCF``, ``LiSPSM``,
``EyeSpaceBlur``) and ``Auto`` are the core's classes (frozen,
keyword-only, compared by value, picklable); their options, defaults and
limits are the core's and :func:`capabilities` publishes them.
An option left ``None`` is resolved when the config runs (the result's
``method`` is the resolved config).
"""

from __future__ import annotations

import functools
import operator
from typing import TYPE_CHECKING, Any, TypeAlias

from . import _core

# The method configs and their parts: the core's `__all__` lists them, made
# from its table, so a new method's class is exported with no line here.
from ._core import *  # noqa: F403
from ._core import MethodInfo, OptionInfo

if TYPE_CHECKING:
    from ._core import Auto, _Ran

    MethodConfig: TypeAlias = _Ran | Auto
else:
    MethodConfig = functools.reduce(operator.or_, (i.config for i in _core.capabilities().values()))
"""Any method config."""


def capabilities() -> dict[str, MethodInfo]:
    """Per method (``"ssm"``, ``"bitmask"``, ``"exact"``, ``"pcss"``,
    ``"smoothies"``, ``"shadow_mapping"``, ``"auto"``): its config class,
    options (kind, default, limits or allowed values, values a backend
    restricts), the backends of this build that run it, and what it reads
    (``"occluder_layers"``, ``"occluder_triangles"``, or for the eye view's
    ``"shadow_mapping"`` ``"scene_triangles"`` and ``"camera"``)."""
    return dict(_core.capabilities())


def limits() -> dict[str, Any]:
    """Limits that are not one method's: ``max_texels`` per map,
    ``max_extent`` (tangent half-extent), ``max_passes``, ``max_samples``
    (``exact``), ``max_threads`` (``threads=``), ``gpu_max_side`` (0
    without a GPU backend), ``max_emission`` (a light's ``radiance`` or
    ``irradiance`` per channel: the largest float32), ``lights`` (the most
    lights one :func:`softshadow.render` call takes), and the cost limits:
    ``visits_per_receiver`` (the weighted occluder texels a gather kernel,
    ``ssm`` or ``bitmask``, may visit per receiver it shades, counted as it
    runs), ``pcss_reads_per_receiver`` (PCSS's texel reads, bounded before
    it runs), each with at least ``min_receivers`` receivers' worth."""
    return dict(_core.limits())


__all__ = ["MethodConfig", "MethodInfo", "OptionInfo", "capabilities", "limits"]
__all__ += _core.__all__
