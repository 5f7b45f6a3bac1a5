"""The lights: rectangular, disk and spherical area lights and the sun
(:class:`RectLight`, :class:`DiskLight`, :class:`SphereLight`,
:class:`DirectionalLight`), with their emission.

Both are the core's classes (``src/python/lights.rs``), like
:class:`softshadow.Camera`: frozen, compared and hashed by value,
picklable; their frames and every value check are the core's
(``src/geom/light.rs``, ``src/geom/sun.rs``).

A light's emission is RGB (a number is grey): an area light's ``radiance``
(emitted uniformly, Lambertian; a rectangle's and a disk's on their ``n``
side only, a sphere's over its whole surface) and the sun's
``irradiance`` (on a surface facing it). Only :func:`softshadow.render`'s
shaded images read it (docs/shading.md); visibility never does. The core
computes the unshadowed irradiance (:meth:`RectLight.irradiance_at`,
src/eye/shading.rs).
"""

from __future__ import annotations

from ._core import DirectionalLight, DiskLight, RectLight, SphereLight

Light = RectLight | DiskLight | SphereLight | DirectionalLight
"""Any light :func:`softshadow.render` takes."""

LIGHT_TYPES = (RectLight, DiskLight, SphereLight, DirectionalLight)
"""The light classes, for ``isinstance``."""

__all__ = ["LIGHT_TYPES", "DirectionalLight", "DiskLight", "Light", "RectLight", "SphereLight"]
