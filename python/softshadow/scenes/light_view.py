"""The built-in light-view scenes: each builder returns ``(scene, light)``,
occluders over receivers (numpy only, no trimesh needed).

The paper's scenes (Atty et al. 2005, §4.2): a square plate parallel to the
light, the bunny floating above the floor and the bunny touching it; plus a
torus and two spheres at different heights. Every scene uses the same setup:
floor y = 0 (a square 8 units wide), light 1 x 1 at height 4 facing down,
``up = +z``; occluders are about 1 unit tall.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..lights import RectLight
from ..scene import Scene
from .primitives import box, bunny_mesh, floor, quad, rotated, sphere, torus

LIGHT_HEIGHT = 4.0


def default_light(size: float = 1.0, height: float = LIGHT_HEIGHT) -> RectLight:
    return RectLight(center=(0.0, height, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(size, size))


def bunny_floating(gap: float = 1.0, light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """The bunny, 1 unit tall, floating ``gap`` above the floor (the paper's Bunny)."""
    return Scene(occluders=[bunny_mesh(1.0, gap)], receivers=[floor()]), default_light(light_size)


def bunny_on_floor(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """The bunny standing on the floor (contact: the shadow hardens)."""
    return Scene(occluders=[bunny_mesh(1.0, 0.0)], receivers=[floor()]), default_light(light_size)


def square_plate(side: float = 1.0, height: float = 2.0, light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """A square plate parallel to the light and the floor (closed form known)."""
    return Scene(occluders=[quad((0.0, height, 0.0), side / 2)], receivers=[floor()]), default_light(light_size)


def torus_floating(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """A flat torus (radii 0.5 and 0.2) centered 1.5 above the floor."""
    return Scene(occluders=[torus((0.0, 1.5, 0.0), 0.5, 0.2)], receivers=[floor()]), default_light(light_size)


def two_spheres(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """Two spheres at different heights whose penumbrae overlap."""
    occ = [sphere((-0.3, 1.0, 0.0), 0.3), sphere((0.35, 2.2, 0.1), 0.3)]
    return Scene(occluders=occ, receivers=[floor()]), default_light(light_size)


# The hard surfaces of the accuracy goal (issue 12): planes tilted against
# the light, slanted receivers, thin bars, contact, a near light. Each keeps
# the shared setup (floor y = 0, light at height 4 facing down).


def tilted_plate(degrees: float = 30.0, light_size: float = 0.5) -> tuple[Scene, RectLight]:
    """A 1 x 1 plate at height 2 tilted ``degrees`` about z: neighbouring
    texels at different depths (the gaps of the SSM's §4.1.2)."""
    plate = rotated(quad((0.0, 2.0, 0.0), 0.5), degrees, "z")
    return Scene(occluders=[plate], receivers=[floor()]), default_light(light_size)


def slanted_receiver(degrees: float = 30.0, light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """A 0.8 x 0.8 plate parallel to the light at height 2 over a floor
    tilted ``degrees`` about x (the receivers' depth varies)."""
    ground = rotated(floor(2.0), degrees, "x", about=(0.0, 0.0, 0.0))
    return Scene(occluders=[quad((0.0, 2.0, 0.0), 0.4)], receivers=[ground]), default_light(light_size)


def fence(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """Seven thin bars (0.03 wide, 0.15 apart) at height 1.2: features a few
    texels wide whose penumbrae overlap."""
    bars = [box((x, 1.2, 0.0), (0.03, 0.03, 1.2)) for x in np.linspace(-0.45, 0.45, 7)]
    return Scene(occluders=bars, receivers=[floor()]), default_light(light_size)


def contact_box(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """A 0.6 cube resting on the floor: the shadow hardens to the contact."""
    return Scene(occluders=[box((0.0, 0.3, 0.0), (0.6, 0.6, 0.6))], receivers=[floor()]), default_light(light_size)


def near_light(light_size: float = 1.0) -> tuple[Scene, RectLight]:
    """A sphere of radius 0.25 at height 3.4, 0.6 below the light: the
    penumbra is wider than the shadow."""
    return Scene(occluders=[sphere((0.0, 3.4, 0.0), 0.25)], receivers=[floor()]), default_light(light_size)


#: The hard surfaces by name; each call builds ``(scene, light)`` afresh.
HARD_SURFACES: dict[str, Callable[[], tuple[Scene, RectLight]]] = {
    "tilted_plate": tilted_plate,
    "slanted_receiver": slanted_receiver,
    "fence": fence,
    "contact_box": contact_box,
    "near_light": near_light,
}


#: The built-in scenes by name; each call builds ``(scene, light)`` afresh.
SCENES: dict[str, Callable[[], tuple[Scene, RectLight]]] = {
    "bunny_floating": bunny_floating,
    "bunny_on_floor": bunny_on_floor,
    "square_plate": square_plate,
    "torus": torus_floating,
    "two_spheres": two_spheres,
}
