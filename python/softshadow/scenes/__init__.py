"""Built-in scenes, built with numpy alone (no trimesh needed).

* :mod:`.primitives`: the meshes they are made of (``quad``, ``floor``,
  ``sphere``, ``torus``, ``box``, ``bunny_mesh``) and ``rotated``; each a
  ``(vertices, faces)`` pair that :class:`softshadow.Scene` takes.
* :mod:`.light_view`: the paper's scenes and the hard surfaces, each builder
  returning ``(Scene, RectLight)``: occluders over a floor under a 1 x 1
  light at height 4 (``SCENES``, ``HARD_SURFACES``).
* :mod:`.eye_view`: scenes that shadow themselves, seen through a camera,
  each builder returning ``(Scene, light, Camera)`` (``EYE_SCENES``).
* :mod:`.as_built`: eye-view scenes built the way users build them (closed
  box floors and walls, thin panels, open and damaged meshes, files through
  ``trimesh.load``, 100 000+ triangles), in a calibration set and a
  held-out set (``CALIBRATION``, ``HELD_OUT``; docs/accuracy.md).

The primitives and the light-view builders are re-exported here
(``softshadow.scenes.bunny_floating()``, ``softshadow.scenes.quad(...)``);
the eye-view builders are reached through their module
(``softshadow.scenes.eye_view.bunny_on_floor((320, 240))``): both views have
a ``bunny_on_floor``, and ``softshadow.scenes.bunny_on_floor`` is the light
view's.
"""

from __future__ import annotations

from . import as_built, eye_view, light_view, primitives
from .light_view import (
    HARD_SURFACES,
    LIGHT_HEIGHT,
    SCENES,
    bunny_floating,
    bunny_on_floor,
    contact_box,
    default_light,
    fence,
    near_light,
    slanted_receiver,
    square_plate,
    tilted_plate,
    torus_floating,
    two_spheres,
)
from .primitives import box, bunny_mesh, floor, quad, rotated, sphere, torus

__all__ = [
    "HARD_SURFACES",
    "LIGHT_HEIGHT",
    "SCENES",
    "as_built",
    "box",
    "bunny_floating",
    "bunny_mesh",
    "bunny_on_floor",
    "contact_box",
    "default_light",
    "eye_view",
    "fence",
    "floor",
    "light_view",
    "near_light",
    "primitives",
    "quad",
    "rotated",
    "slanted_receiver",
    "sphere",
    "square_plate",
    "tilted_plate",
    "torus",
    "torus_floating",
    "two_spheres",
]
