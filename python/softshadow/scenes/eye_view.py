"""The built-in eye-view scenes: every mesh casts and receives, seen through a
camera (numpy only). Each builder returns ``(scene, light, camera)`` at the
resolution asked for; the tests check them against Mitsuba and
``benchmarks/bench_eye.py`` times them.

* ``bunny_on_floor``: the bundled bunny standing on a floor under a 1 x 1
  light off to its side: it shadows itself and the floor, in contact.
* ``torus``: a tilted torus over a floor; its ring shadows its own far side.
* ``contact_boxes``: two boxes and a sphere resting on a floor, touching,
  under a large light close above (wide penumbrae that harden at contact).
* ``city``: a block of 6 x 6 box buildings of varied heights lit by a small
  sun (0.53 degrees), seen from above at an angle.

Reached as ``softshadow.scenes.eye_view.<builder>``, not re-exported by
:mod:`softshadow.scenes`, whose ``bunny_on_floor`` is the light view's.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..lights import DirectionalLight, RectLight
from ..scene import Camera, Scene
from .primitives import box, bunny_mesh, quad, rotated, sphere, torus

EyeScene = tuple[Scene, RectLight | DirectionalLight, Camera]


def bunny_on_floor(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    scene = Scene(meshes=[bunny_mesh(1.0, 0.0), quad((0.0, 0.0, 0.0), 4.0)])
    light = RectLight(center=(1.5, 3.5, 1.0), normal=(-1.5, -3.5, -1.0), up=(0.0, 0.0, 1.0), size=(1.0, 1.0))
    cam = Camera.look_at(
        eye=(2.2, 1.6, 2.8), target=(0.0, 0.4, 0.0), up=(0.0, 1.0, 0.0), fov_y=35.0, resolution=resolution
    )
    return scene, light, cam


def torus_self(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    ring = rotated(torus((0.0, 0.9, 0.0), 0.6, 0.22), 55.0, "x", about=(0.0, 0.9, 0.0))
    scene = Scene(meshes=[ring, quad((0.0, 0.0, 0.0), 4.0)])
    light = RectLight(center=(0.3, 4.0, 0.8), normal=(-0.3, -4.0, -0.8), up=(0.0, 0.0, 1.0), size=(0.8, 0.8))
    cam = Camera.look_at(
        eye=(2.4, 1.9, 2.2), target=(0.0, 0.7, 0.0), up=(0.0, 1.0, 0.0), fov_y=38.0, resolution=resolution
    )
    return scene, light, cam


def contact_boxes(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    meshes = [
        box((-0.45, 0.35, 0.0), (0.7, 0.7, 0.7)),
        box((0.45, 0.25, -0.1), (0.5, 0.5, 0.9)),
        sphere((0.1, 0.3, 0.65), 0.3),
        quad((0.0, 0.0, 0.0), 4.0),
    ]
    scene = Scene(meshes=meshes)
    light = RectLight(center=(0.2, 2.0, 0.4), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(2.5, 2.5))
    cam = Camera.look_at(
        eye=(1.9, 1.5, 2.4), target=(0.0, 0.25, 0.1), up=(0.0, 1.0, 0.0), fov_y=40.0, resolution=resolution
    )
    return scene, light, cam


def city(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    rng = np.random.default_rng(7)
    meshes = []
    for i in range(6):
        for j in range(6):
            h = float(rng.uniform(0.3, 1.6))
            meshes.append(box((-2.5 + i, h / 2, -2.5 + j), (0.6, h, 0.6)))
    meshes.append(quad((0.0, 0.0, 0.0), 5.0))
    scene = Scene(meshes=meshes)
    sun = DirectionalLight(direction=(0.8, -0.7, -0.3), up=(0.0, 1.0, 0.0), angular_size=(0.53, 0.53))
    cam = Camera.look_at(
        eye=(5.5, 5.0, 6.0), target=(0.0, 0.3, 0.0), up=(0.0, 1.0, 0.0), fov_y=40.0, resolution=resolution
    )
    return scene, sun, cam


def large_city(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Scherzer's setting: a large scene under the sun seen from near the
    ground. 40 x 40 blocks of buildings (2 to 18 units tall, 10 apart) on a
    400-unit ground, the camera 1.7 units up in the middle looking along a
    street (a 35-degree vertical field of view), the sun across the view
    (its direction at about 80 degrees to the view's), as in the paper's
    "near perpendicular view and light"."""
    rng = np.random.default_rng(11)
    meshes = []
    for i in range(40):
        for j in range(40):
            h = float(rng.uniform(2.0, 18.0))
            w = float(rng.uniform(3.0, 6.0))
            meshes.append(box((-195.0 + 10 * i, h / 2, -195.0 + 10 * j), (w, h, w)))
    meshes.append(quad((0.0, 0.0, 0.0), 200.0))
    scene = Scene(meshes=meshes)
    sun = DirectionalLight(direction=(0.15, -0.6, -0.8), up=(0.0, 1.0, 0.0), angular_size=(0.53, 0.53))
    cam = Camera.look_at(
        eye=(0.0, 1.7, 0.0), target=(100.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov_y=35.0, resolution=resolution
    )
    return scene, sun, cam


#: The eye-view scenes by name; each call builds ``(scene, light, camera)`` afresh.
EYE_SCENES: dict[str, Callable[..., EyeScene]] = {
    "bunny_on_floor": bunny_on_floor,
    "torus": torus_self,
    "contact_boxes": contact_boxes,
    "city": city,
}
