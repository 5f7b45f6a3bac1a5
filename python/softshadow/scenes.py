"""Built-in test scenes, built with numpy alone (no trimesh needed).

The paper's scenes (Atty et al. 2005, §4.2): a square plate parallel to the
light, the bunny floating above the floor and the bunny touching it; plus a
torus and two spheres at different heights. Every scene uses the same setup:
floor y = 0 (a square 8 units wide), light 1 x 1 at height 4 facing down,
``up = +z``; occluders are about 1 unit tall.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import resources

import numpy as np

from .light import RectLight
from .scene import Mesh, Scene

LIGHT_HEIGHT = 4.0


def default_light(size: float = 1.0, height: float = LIGHT_HEIGHT) -> RectLight:
    return RectLight(center=(0.0, height, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(size, size))


def quad(center: tuple[float, float, float], half: float) -> Mesh:
    """A horizontal square (normal +y) of half-size ``half``."""
    cx, cy, cz = center
    v = np.array(
        [[cx - half, cy, cz - half], [cx + half, cy, cz - half], [cx + half, cy, cz + half], [cx - half, cy, cz + half]]
    )
    return v, np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32)


def floor(half: float = 4.0) -> Mesh:
    return quad((0.0, 0.0, 0.0), half)


def sphere(center: tuple[float, float, float], radius: float, n: int = 48) -> Mesh:
    """A UV sphere with ``n`` segments around and ``n // 2`` rings."""
    rings = max(n // 2, 2)
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring_pts = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    verts = np.vstack([[0.0, 1.0, 0.0], ring_pts, [0.0, -1.0, 0.0]]) * radius + np.asarray(center)
    faces = []
    top, bottom = 0, len(verts) - 1

    def idx(r: int, s: int) -> int:
        return 1 + r * n + s % n

    for s in range(n):
        faces.append([top, idx(0, s + 1), idx(0, s)])
        faces.append([bottom, idx(rings - 2, s), idx(rings - 2, s + 1)])
        for r in range(rings - 2):
            a, b, c, d = idx(r, s), idx(r, s + 1), idx(r + 1, s + 1), idx(r + 1, s)
            faces += [[a, b, c], [a, c, d]]
    return verts, np.asarray(faces, dtype=np.uint32)


def torus(center: tuple[float, float, float], major: float, minor: float, n_major: int = 64, n_minor: int = 32) -> Mesh:
    """A torus lying flat (axis +y)."""
    a = np.linspace(0, 2 * np.pi, n_major, endpoint=False)
    b = np.linspace(0, 2 * np.pi, n_minor, endpoint=False)
    A, B = np.meshgrid(a, b, indexing="ij")
    r = major + minor * np.cos(B)
    verts = np.stack([r * np.cos(A), minor * np.sin(B), r * np.sin(A)], axis=-1).reshape(-1, 3) + np.asarray(center)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    p00 = i * n_minor + j
    p10 = ((i + 1) % n_major) * n_minor + j
    p11 = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
    p01 = i * n_minor + (j + 1) % n_minor
    faces = np.concatenate([np.stack([p00, p01, p11], -1).reshape(-1, 3), np.stack([p00, p11, p10], -1).reshape(-1, 3)])
    return verts, faces.astype(np.uint32)


def bunny_mesh(height: float = 1.0, base: float = 0.0) -> Mesh:
    """The bundled Stanford bunny, scaled to ``height`` units tall, centered over
    the origin in x and z, its lowest point at y = ``base``."""
    with resources.files(__package__).joinpath("data/bunny.npz").open("rb") as f:
        data = np.load(f)
        v = data["vertices"].astype(np.float64)
        faces = data["faces"].astype(np.uint32)
    lo, hi = v.min(axis=0), v.max(axis=0)
    s = height / (hi[1] - lo[1])
    center = 0.5 * (lo + hi)
    v = (v - center) * s
    v[:, 1] += base - v[:, 1].min()
    return v, faces


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


#: The built-in scenes by name; each call builds ``(scene, light)`` afresh.
SCENES: dict[str, Callable[[], tuple[Scene, RectLight]]] = {
    "bunny_floating": bunny_floating,
    "bunny_on_floor": bunny_on_floor,
    "square_plate": square_plate,
    "torus": torus_floating,
    "two_spheres": two_spheres,
}
