"""Ground-truth soft-shadow visibility and images computed with Mitsuba 3.

This package is optional: ``import softshadow`` never imports it, and it needs
the ``reference`` extra (``pip install softshadow[reference]``), i.e. Mitsuba 3
and Dr.Jit. Mitsuba is imported lazily, on the first call that needs it, so
merely importing this package is cheap and never fails; the import only
points ``DRJIT_LIBLLVM_PATH`` at the newest libLLVM >= 16 on the system when
neither the user nor an earlier import of Dr.Jit has settled it (see
``_mitsuba``).

Conventions (shared with the rest of the package)
-------------------------------------------------
A rectangular light has a ``center`` c, a ``normal`` pointing from the light
into the scene, an ``up`` vector and a ``size`` (sx, sy). Its frame is
``n = normalize(normal)``, ``v = normalize(up - (up.n) n)``, ``u = n x v``;
``sx`` is the full width along u and ``sy`` the full height along v.

The visibility of a point is the fraction of the light's *area* that can be
seen from it (uniform over the rectangle, no cosine weighting), where only the
occluder meshes block light: receivers never cast shadows.

Variant
-------
Mitsuba's variant is process-global. The first call picks ``llvm_ad_rgb`` when
Dr.Jit can load libLLVM >= 16 (older versions crash Dr.Jit) and ``scalar_rgb``
otherwise, and selects it once; see :func:`variant`. The scalar variant traces
one ray per Python call (about a million rays per second), which is fine for
tests but slow for full-resolution references.

Modules
-------
``_mitsuba``
    Mitsuba and Dr.Jit loading, the libLLVM lookup, variant choice, and the
    Mitsuba objects (meshes, the light's rectangle).
``_inputs``
    Argument validation and the light's frame (NumPy only).
``_rays``
    Stratified jittered shadow rays and their batching.
``visibility``
    :class:`ReferenceScene`, :func:`visibility_at_points`, :func:`reference_map`.
``render``
    :func:`render_image`.
``camera``
    :func:`camera_sensor`: Mitsuba's sensor for a :class:`softshadow.Camera`.
``eye``
    :func:`render_visibility`, :class:`ReferenceImage`: the visibility of the
    surface seen through each pixel of a camera, under a rectangular or a
    directional light, every mesh casting shadows (itself included), with
    the first hits' mask, depth, position, normal and mesh index.
``shading``
    :func:`render_direct`: the radiance toward the camera at each pixel
    centre from Mitsuba's ``direct`` integrator (two-sided diffuse meshes,
    the light as an area or directional emitter): the ground truth of
    ``softshadow.render``'s shaded images.
"""

from __future__ import annotations

# VARIANT_ENV (the variable forcing the variant), MAX_RAYS_PER_BATCH and
# _import_mitsuba stay importable from here, outside __all__. The batch size
# is read where it is defined: to change it, set
# softshadow.reference._rays.MAX_RAYS_PER_BATCH.
from ._mitsuba import VARIANT_ENV as VARIANT_ENV
from ._mitsuba import _import_mitsuba as _import_mitsuba
from ._mitsuba import variant
from ._rays import MAX_RAYS_PER_BATCH as MAX_RAYS_PER_BATCH
from .camera import camera_sensor
from .eye import ReferenceImage, render_visibility
from .render import render_image
from .shading import render_direct
from .visibility import ReferenceScene, TraceStats, reference_map, visibility_at_points

__all__ = [
    "camera_sensor",
    "ReferenceImage",
    "ReferenceScene",
    "TraceStats",
    "render_direct",
    "render_image",
    "render_visibility",
    "reference_map",
    "variant",
    "visibility_at_points",
]
