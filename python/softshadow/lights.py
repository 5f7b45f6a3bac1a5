"""The lights: a rectangular area light and the sun (:class:`RectLight`,
:class:`DirectionalLight`), with their emission.

Both are the core's classes (``src/python/lights.rs``), like
:class:`softshadow.Camera`: frozen, compared and hashed by value,
picklable; their frames and every value check are the core's
(``src/geom/light.rs``, ``src/geom/sun.rs``).

A light's emission is RGB (a number is grey): a rectangle's ``radiance``
(emitted uniformly, Lambertian, on its ``n`` side only) and the sun's
``irradiance`` (on a surface facing it). Only :func:`softshadow.render`'s
shaded images read it (docs/shading.md); visibility never does. The core
computes the unshadowed irradiance (:meth:`RectLight.irradiance_at`,
src/eye/shading.rs).
"""

from __future__ import annotations

from ._core import DirectionalLight, RectLight

__all__ = ["DirectionalLight", "RectLight"]
