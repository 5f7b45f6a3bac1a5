"""The pinhole camera of the eye view (:class:`Camera`).

It is the core's class: the conventions and every value check live in
``src/geom/camera.rs`` (docs/conventions.md#camera).
"""

from __future__ import annotations

from ._core import Camera

__all__ = ["Camera"]
