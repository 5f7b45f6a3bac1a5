"""An item's scene, light and camera from its sampled parameters (:mod:`.sampling`).

Base meshes are centred on their bounding box and scaled so that its
largest side is 1 (the bunny of :func:`softshadow.scenes.bunny_mesh`, a
unit box, a sphere of diameter 1, a torus lying flat with outer diameter 1
and tube radius 0.15, or a mesh file read by trimesh); each process caches
them. Mesh order in the scene: the instances in the record's order, then
the ground, so an image's ``mesh_id`` indexes the record's ``objects`` (the
ground is the last id).

A mesh file the reader refuses raises :class:`MeshError` naming the file
and the reader's complaint (trimesh's own messages, "Not a ply file!",
often do not): the spec's loading reads every file once this way
(:func:`check_mesh_file`), so a broken one is refused before any item.
"""

from __future__ import annotations

import functools
import os
from typing import Any

import numpy as np

from .._extras import require
from ..lights import DirectionalLight, RectLight
from ..scene import Camera, Mesh, Scene
from ..scenes.primitives import box, bunny_mesh, quad, sphere, torus


class MeshError(ValueError):
    """A mesh file that cannot be used; the message names it and why. Not
    retried (:mod:`.book`): a broken input file stays broken."""


@functools.lru_cache(maxsize=64)
def base_mesh(kind: str, path: str | None = None) -> Mesh:
    """The normalized base mesh (read-only arrays): bounding box centred at the origin, largest side 1."""
    if kind == "bunny":
        v, f = bunny_mesh(1.0, 0.0)
    elif kind == "box":
        v, f = box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    elif kind == "sphere":
        v, f = sphere((0.0, 0.0, 0.0), 0.5)
    elif kind == "torus":
        v, f = torus((0.0, 0.0, 0.0), 0.35, 0.15)
    elif kind == "mesh" and path is not None:
        v, f = _read_mesh(path)
    else:
        raise ValueError(f"kind: unknown object kind {kind!r}")
    lo, hi = v.min(axis=0), v.max(axis=0)
    side = float((hi - lo).max())
    if not np.isfinite(side) or side <= 0.0:
        raise (MeshError if path else ValueError)(f"{path or kind}: the mesh has no finite, non-zero extent")
    v = (v - 0.5 * (lo + hi)) / side
    v.setflags(write=False)
    f = np.ascontiguousarray(f, dtype=np.uint32)
    f.setflags(write=False)
    return v, f


def _read_mesh(path: str) -> Mesh:
    trimesh = require("trimesh", "dataset", 'an object of kind = "mesh"')
    try:
        loaded = trimesh.load(path, force="mesh")
    except Exception as e:  # trimesh's readers raise anything: ValueError, IndexError, KeyError, ...
        raise MeshError(f"{path}: trimesh cannot read it ({type(e).__name__}: {e})") from e
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshError(f"{path}: trimesh found no triangles")
    v, f = np.asarray(loaded.vertices, dtype=np.float64), np.asarray(loaded.faces)
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        raise MeshError(f"{path}: a face indexes vertex {int(f.max())} of {len(v)}")
    return v, f


def check_mesh_file(path: str) -> None:
    """Reads and normalizes a mesh file as an item would (cached); MeshError if it cannot be used."""
    base_mesh("mesh", path)


def _rotation(axis: np.ndarray, degrees: float) -> np.ndarray:
    """Rodrigues' rotation matrix about a unit axis."""
    a = np.radians(degrees)
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(a) * k + (1.0 - np.cos(a)) * (k @ k)


def place(inst: dict[str, Any], folder: str) -> Mesh:
    """One instance's world-space mesh (see :mod:`.sampling` for the order of the steps)."""
    path = os.path.join(folder, inst["file"]) if inst["kind"] == "mesh" else None
    v, f = base_mesh(inst["kind"], path)
    v = v * (np.asarray(inst["stretch"]) * inst["scale"])
    t = np.radians(inst["tilt_axis"])
    v = v @ _rotation(np.array([np.cos(t), 0.0, np.sin(t)]), inst["tilt"]).T
    v = v @ _rotation(np.array([0.0, 1.0, 0.0]), inst["yaw"]).T
    lo, hi = v.min(axis=0), v.max(axis=0)
    v = v + np.array([inst["x"] - 0.5 * (lo[0] + hi[0]), inst["height"] - lo[1], inst["z"] - 0.5 * (lo[2] + hi[2])])
    return v, f


def build_scene(params: dict[str, Any], folder: str) -> tuple[Scene, list[np.ndarray]]:
    """The scene and each mesh's RGB albedo, in scene order."""
    meshes = [place(inst, folder) for inst in params["objects"]]
    albedo = [np.asarray(inst["albedo"]) for inst in params["objects"]]
    if params["ground"] is not None:
        meshes.append(quad((0.0, 0.0, 0.0), 0.5 * params["ground"]["size"]))
        albedo.append(np.asarray(params["ground"]["albedo"]))
    return Scene(meshes=meshes), albedo


def build_light(p: dict[str, Any], *, shading: bool) -> RectLight | DirectionalLight:
    """The light; with ``shading`` its ``radiance`` or ``irradiance`` too."""
    extra: dict[str, Any] = {}
    if p["kind"] == "rect":
        if shading:
            extra["radiance"] = p["radiance"]
        return RectLight(center=p["center"], normal=p["normal"], up=p["up"], size=p["size"], **extra)
    if shading:
        extra["irradiance"] = p["irradiance"]
    return DirectionalLight(direction=p["direction"], up=p["up"], angular_size=p["angular_size"], **extra)


def build_camera(p: dict[str, Any]) -> Camera:
    w, h = p["resolution"]
    return Camera.look_at(eye=p["eye"], target=p["target"], up=p["up"], fov_y=p["fov_y"], resolution=(w, h))
