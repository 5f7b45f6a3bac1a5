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

from .lights import RectLight
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


def box(center: tuple[float, float, float], size: tuple[float, float, float]) -> Mesh:
    """An axis-aligned box (12 triangles, outward normals)."""
    c, h = np.asarray(center, dtype=np.float64), 0.5 * np.asarray(size, dtype=np.float64)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    faces = [
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # x = -1, x = +1
        [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # y = -1, y = +1
        [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # z = -1, z = +1
    ]  # fmt: skip
    return corners * h + c, np.asarray(faces, dtype=np.uint32)


def rotated(mesh: Mesh, degrees: float, axis: str, about: tuple[float, float, float] | None = None) -> Mesh:
    """``mesh`` turned by ``degrees`` about the ``axis`` ("x", "y" or "z")
    through ``about`` (default: the centre of its bounding box)."""
    v, f = mesh
    t = np.deg2rad(degrees)
    c, s = np.cos(t), np.sin(t)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    o = 0.5 * (v.min(axis=0) + v.max(axis=0)) if about is None else np.asarray(about, dtype=np.float64)
    return (v - o) @ r.T + o, f


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
