"""An item's scene, light and camera from its sampled parameters (:mod:`.sampling`).

Base meshes are centred on their bounding box and scaled so that its
largest side is 1 (the bunny of :func:`softshadow.scenes.bunny_mesh`, a
unit box, a sphere of diameter 1, a torus lying flat with outer diameter 1
and tube radius 0.15, or a mesh file read by trimesh); each process caches
them (the last 64 files read, with their colours). Mesh order in the scene:
the instances in the record's order, then the ground, so an image's
``mesh_id`` indexes the record's ``objects`` (the ground is the last id).

Albedo: every instance and the ground have their sampled ``albedo``. An
instance whose record says ``"colors": "file"`` (a ``kind = "mesh"`` object
with ``colors = "file"``, the default, drawing a file that carries colours)
keeps the file's own colours instead: its :class:`softshadow.Material`
(vertex or face colours, a material's colour, a texture with its UVs; see
:meth:`softshadow.Material.from_trimesh`). ``render``'s ``albedo=``
overrides every material, so a scene with such an instance gives the other
meshes a constant material of their sampled albedo (``scene.materials``)
and is rendered without ``albedo=``; a scene without one is rendered with
``albedo=`` as before (:func:`render_albedo`).

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
from ..lights import DirectionalLight, DiskLight, Light, RectLight, SphereLight
from ..materials import Material
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
        return mesh_file(path)[:2]
    else:
        raise ValueError(f"kind: unknown object kind {kind!r}")
    return _normalized(v, f, None, kind)


def _normalized(v: np.ndarray, f: np.ndarray, path: str | None, kind: str = "mesh") -> Mesh:
    """Centred on its bounding box, its largest side 1; read-only arrays."""
    lo, hi = v.min(axis=0), v.max(axis=0)
    side = float((hi - lo).max())
    if not np.isfinite(side) or side <= 0.0:
        raise (MeshError if path else ValueError)(f"{path or kind}: the mesh has no finite, non-zero extent")
    v = (v - 0.5 * (lo + hi)) / side
    v.setflags(write=False)
    f = np.ascontiguousarray(f, dtype=np.uint32)
    f.setflags(write=False)
    return v, f


MeshFile = tuple[np.ndarray, np.ndarray, Material | None, str | None]
"""A mesh file read: its normalized vertices and faces (read-only), its
colours (None where it has none) and why its colours cannot be used (None
where they can, or where it has none)."""


@functools.lru_cache(maxsize=64)
def mesh_file(path: str) -> MeshFile:
    """The mesh file ``path`` read (cached per process): see :data:`MeshFile`."""
    v, f, material, problem = _read_mesh(path)
    v, f = _normalized(v, f, path)
    if material is not None and material.texture is not None:
        import softshadow as ss

        h, w = material.texture.shape[:2]
        most = int(ss.limits().get("max_texels", 1 << 28))
        if h * w > most:
            material, problem = None, f"its texture has {w}x{h} texels; at most {most}"
    return v, f, material, problem


def file_material(path: str) -> Material | None:
    """The colours of the mesh file ``path`` (None where it has none or they cannot be used)."""
    return mesh_file(path)[2]


def _read_mesh(path: str) -> tuple[np.ndarray, np.ndarray, Material | None, str | None]:
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
    try:
        return v, f, Material.from_trimesh(loaded, "its visual"), None
    except (ValueError, TypeError) as e:
        return v, f, None, str(e)


def check_mesh_file(path: str, *, colors: bool = False) -> bool:
    """Reads and normalizes a mesh file as an item would (cached); MeshError
    if it cannot be used (with ``colors``, if its colours cannot be used
    either). Returns whether it carries colours."""
    _, _, material, problem = mesh_file(path)
    if colors and problem is not None:
        raise MeshError(f'{path}: its colours cannot be used ({problem}); colors = "albedo" uses the geometry alone')
    return material is not None


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
    """The scene and each mesh's sampled RGB albedo, in scene order. Where an
    instance keeps its file's colours (``"colors": "file"``), the scene's
    ``materials`` hold them, and a constant material of its albedo for every
    other mesh (module docstring); render it without ``albedo=``
    (:func:`render_albedo`)."""
    meshes = [place(inst, folder) for inst in params["objects"]]
    albedo = [np.asarray(inst["albedo"]) for inst in params["objects"]]
    own: list[Material | None] = [
        file_material(os.path.join(folder, inst["file"])) if inst.get("colors") == "file" else None
        for inst in params["objects"]
    ]
    if params["ground"] is not None:
        meshes.append(quad((0.0, 0.0, 0.0), 0.5 * params["ground"]["size"]))
        albedo.append(np.asarray(params["ground"]["albedo"]))
        own.append(None)
    materials = None
    if any(m is not None for m in own):
        materials = [
            m if m is not None else Material("constant", color=(float(a[0]), float(a[1]), float(a[2])))
            for m, a in zip(own, albedo, strict=True)
        ]
    return Scene(meshes=meshes, materials=materials), albedo


def render_albedo(scene: Scene, albedo: list[np.ndarray]) -> dict[str, Any]:
    """``render``'s albedo argument for a scene of :func:`build_scene`:
    ``{"albedo": [...]}`` (one RGB per mesh), or nothing where the scene's
    materials hold the colours (``albedo=`` would override them)."""
    if any(m is not None for m in scene.materials):
        return {}
    return {"albedo": [tuple(float(c) for c in a) for a in albedo]}


def build_light(p: dict[str, Any], *, shading: bool) -> Light:
    """The light; with ``shading`` its ``radiance`` or ``irradiance`` too."""
    extra: dict[str, Any] = {}
    kind = p["kind"]
    if kind == "sun":
        if shading:
            extra["irradiance"] = p["irradiance"]
        return DirectionalLight(direction=p["direction"], up=p["up"], angular_size=p["angular_size"], **extra)
    if shading:
        extra["radiance"] = p["radiance"]
    if kind == "rect":
        return RectLight(center=p["center"], normal=p["normal"], up=p["up"], size=p["size"], **extra)
    if kind == "disk":
        return DiskLight(center=p["center"], normal=p["normal"], radius=p["radius"], **extra)
    if kind == "sphere":
        return SphereLight(center=p["center"], radius=p["radius"], **extra)
    raise ValueError(f"kind: unknown light kind {kind!r}")


def record_lights(params: dict[str, Any]) -> list[dict[str, Any]]:
    """An item's lights as its record holds them: ``lights`` (a spec with
    ``lights_per_item`` above 1), else the one ``light``."""
    return list(params["lights"]) if "lights" in params else [params["light"]]


def build_lights(params: dict[str, Any], *, shading: bool) -> Light | list[Light]:
    """What ``render`` takes for the item: a list of its lights where its
    record has ``lights`` (even one), else its one light alone (as before
    several lights per item; the channels are ``V`` then, not ``V.0``)."""
    lights = [build_light(p, shading=shading) for p in record_lights(params)]
    return lights if "lights" in params else lights[0]


def build_camera(p: dict[str, Any]) -> Camera:
    w, h = p["resolution"]
    return Camera.look_at(eye=p["eye"], target=p["target"], up=p["up"], fov_y=p["fov_y"], resolution=(w, h))
