"""The built-in scenes' primitives, numpy only: a horizontal quad and the
floor, a UV sphere, a flat torus, an axis-aligned box, the bundled Stanford
bunny, and :func:`rotated` (a mesh turned about an axis). Each returns a
``(vertices (n, 3) float64, faces (m, 3) uint32)`` pair, which
:class:`softshadow.Scene` takes as a mesh.
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from ..scene import Mesh

__all__ = ["box", "bunny_mesh", "floor", "quad", "rotated", "sphere", "torus"]


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
    with resources.files("softshadow").joinpath("data/bunny.npz").open("rb") as f:
        data = np.load(f)
        v = data["vertices"].astype(np.float64)
        faces = data["faces"].astype(np.uint32)
    lo, hi = v.min(axis=0), v.max(axis=0)
    s = height / (hi[1] - lo[1])
    center = 0.5 * (lo + hi)
    v = (v - center) * s
    v[:, 1] += base - v[:, 1].min()
    return v, faces


def box(center: tuple[float, float, float], size: tuple[float, float, float]) -> Mesh:
    """An axis-aligned closed box (12 triangles, outward normals) of full side
    lengths ``size`` (x, y, z)."""
    c, h = np.asarray(center, dtype=np.float64), 0.5 * np.asarray(size, dtype=np.float64)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    # Corner index = 4 (x > 0) + 2 (y > 0) + (z > 0).
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
