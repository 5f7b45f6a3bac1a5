"""What is seen, and from where: the :class:`Scene` (meshes that all cast
and receive shadows, or the paper's split: occluders cast shadows, receivers
catch them; with the colours their files carry, :mod:`.materials`) and the
eye view's pinhole :class:`Camera`.

``Camera`` is the core's class (frozen, compared by value, picklable): its
conventions and every value check live in ``src/geom/camera.rs``
(docs/conventions.md#camera).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from . import _core
from ._core import Camera
from .materials import Material

Mesh = tuple[np.ndarray, np.ndarray]

__all__ = ["Camera", "Mesh", "Scene", "as_mesh"]


def as_mesh(obj: Any, name: str) -> Mesh:
    """(vertices float64 (n, 3), faces uint32 (m, 3)) from a trimesh.Trimesh,
    any object with ``vertices`` and ``faces``, or a (vertices, faces) pair."""
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        verts, faces = obj.vertices, obj.faces
    elif isinstance(obj, (tuple, list)) and len(obj) == 2:
        verts, faces = obj
    else:
        raise TypeError(f"{name}: must be a trimesh.Trimesh or a (vertices, faces) pair, got {type(obj).__name__}")
    v = np.asarray(verts)
    f = np.asarray(faces)
    if v.dtype.kind not in "fiu":
        raise TypeError(f"{name}: vertices must be numbers, got dtype {v.dtype}")
    if f.dtype.kind not in "iu":
        raise TypeError(f"{name}: faces must be integers, got dtype {f.dtype}")
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name}: vertices must have shape (n, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"{name}: faces must have shape (m, 3), got {f.shape}")
    v = np.ascontiguousarray(v, dtype=np.float64)
    # The conversion to the core's uint32 indices must not wrap; the values
    # (finite vertices, indices below the vertex count) are the core's to check.
    if f.size and (f.min() < 0 or f.max() > np.iinfo(np.uint32).max):
        raise ValueError(f"{name}: face indices must lie in [0, 2^32), got [{f.min()}, {f.max()}]")
    faces32 = np.ascontiguousarray(f, dtype=np.uint32)
    _core.check_mesh(name, v, faces32)
    return v, faces32


def _concat(meshes: list[Mesh]) -> Mesh:
    if not meshes:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32)
    offsets = np.cumsum([0] + [len(v) for v, _ in meshes[:-1]])
    verts = np.concatenate([v for v, _ in meshes])
    faces = np.concatenate([f + np.uint32(o) for (_, f), o in zip(meshes, offsets, strict=True)])
    return np.ascontiguousarray(verts), np.ascontiguousarray(faces, dtype=np.uint32)


class Scene:
    """Meshes that cast and receive shadows.

    ``Scene(meshes=[...])``: every mesh casts shadows on every mesh, itself
    included (what :func:`softshadow.render` draws). ``Scene(occluders=...,
    receivers=...)``: the split of Atty et al. 2005, where occluders shadow
    receivers and neither shadows itself (what :func:`soft_shadow_map` maps;
    in :func:`softshadow.render` its meshes are occluders then receivers, and
    every one casts and receives).

    Each argument is one mesh or an iterable of meshes; a mesh is a
    ``trimesh.Trimesh`` (or anything with ``vertices`` and ``faces``) or a
    ``(vertices (n, 3), faces (m, 3))`` pair. The constructor keeps the
    geometry, and ``materials=`` (keyword-only) the colours: one
    :class:`~softshadow.materials.Material` or None per mesh of ``meshes``,
    each checked against its mesh (default: all None);
    :meth:`from_trimesh` reads them from the file.
    """

    def __init__(
        self, occluders: Any = None, receivers: Any = None, *, meshes: Any = None, materials: Any = None
    ) -> None:
        if meshes is not None and (occluders is not None or receivers is not None):
            raise TypeError("meshes: pass either meshes or occluders and receivers, not both")
        if meshes is None and (occluders is None or receivers is None):
            raise TypeError(
                "meshes: pass meshes=[...] (every mesh casts and receives), or both occluders and receivers"
            )
        self.split = meshes is None
        if self.split:
            self.occluders: list[Mesh] = self._meshes(occluders, "occluders")
            self.receivers: list[Mesh] = self._meshes(receivers, "receivers")
            if not any(len(f) for _, f in self.occluders):
                raise ValueError("occluders: the scene has no occluder triangles")
            if not any(len(f) for _, f in self.receivers):
                raise ValueError("receivers: the scene has no receiver triangles")
            self.meshes: list[Mesh] = self.occluders + self.receivers
        else:
            self.meshes = self._meshes(meshes, "meshes")
            if not any(len(f) for _, f in self.meshes):
                raise ValueError("meshes: the scene has no triangles")
            self.occluders = self.meshes
            self.receivers = self.meshes
        self._occ = _concat(self.occluders)
        # Every mesh casts and receives: one mesh serves as both.
        self._rec = _concat(self.receivers) if self.split else self._occ
        self._materials = self._checked_materials(materials)
        self._prepared = _core.Prepared()

    def _checked_materials(self, materials: Any) -> tuple[Material | None, ...]:
        """``materials=``: None (no colours), or one Material or None per
        mesh of ``meshes``, each fitting its mesh; TypeError or ValueError
        naming ``materials`` (``materials[k]``) otherwise."""
        if materials is None:
            return (None,) * len(self.meshes)
        if not isinstance(materials, (list, tuple)):
            raise TypeError(f"materials: must be a list of softshadow.Material or None, got {type(materials).__name__}")
        if len(materials) != len(self.meshes):
            raise ValueError(f"materials: {len(materials)} materials for {len(self.meshes)} meshes")
        for k, (m, (v, f)) in enumerate(zip(materials, self.meshes, strict=True)):
            if m is None:
                continue
            if not isinstance(m, Material):
                raise TypeError(f"materials[{k}]: must be a softshadow.Material or None, got {type(m).__name__}")
            m.check(f"materials[{k}]", len(v), len(f))
        return tuple(materials)

    @property
    def materials(self) -> tuple[Material | None, ...]:
        """One :class:`~softshadow.materials.Material` (or None: no colour in
        the file) per mesh of ``meshes``, in its order: the colours
        :meth:`from_trimesh` read (vertex, face, material and texture
        colours); all None for a scene built from meshes directly."""
        return self._materials

    @property
    def prepared(self) -> _core.Prepared:
        """What renders of this scene built and keep for the next ones (the
        checked triangles; the shadow rays' BVH per light orientation, refitted
        to the next camera): filled by :func:`softshadow.render`, checked
        against the meshes at every call (a mesh changed in place, replaced or
        added starts it again), safe to share between threads. Not pickled."""
        return self._prepared

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        del state["_prepared"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        # A scene pickled before materials existed has none.
        state.setdefault("_materials", (None,) * len(state["meshes"]))
        self.__dict__.update(state)
        self._prepared = _core.Prepared()

    @classmethod
    def from_trimesh(cls, obj: Any) -> Scene:
        """Every mesh of a ``trimesh.Scene`` (its node transforms applied; a
        mesh instanced by several nodes appears once per node), a
        ``trimesh.Trimesh``, or a path trimesh can load. Geometry without
        faces (paths, point clouds) is skipped; a scene with no triangles
        raises ValueError; without trimesh, MissingExtraError naming the
        ``io`` extra.

        The colours come along: ``materials`` holds each mesh's
        :class:`~softshadow.materials.Material` (vertex or face colours, a
        glTF ``baseColorFactor`` or OBJ ``Kd``, a base-colour texture with
        its UVs; None where the mesh has trimesh's default grey), an
        instanced mesh's repeated for every node. A path is loaded with
        ``trimesh.load(path)``, which keeps the materials and textures (no
        ``skip_materials``). Colours whose shape does not match their mesh
        raise ValueError naming ``meshes[k]``."""
        import os

        from ._extras import require

        trimesh = require("trimesh", "io", "Scene.from_trimesh")
        if isinstance(obj, (str, os.PathLike)):
            obj = trimesh.load(os.fspath(obj))
        if isinstance(obj, trimesh.Trimesh):
            return cls(meshes=[obj], materials=[Material.from_trimesh(obj, "meshes[0]")])
        if not isinstance(obj, trimesh.Scene):
            raise TypeError(f"obj: must be a trimesh.Scene, a trimesh.Trimesh or a path, got {type(obj).__name__}")
        meshes: list[Mesh] = []
        materials: list[Material | None] = []
        # One Material per geometry, shared by the nodes that instance it.
        read: dict[str, Material | None] = {}
        for node in obj.graph.nodes_geometry:
            transform, name = obj.graph[node]
            geom = obj.geometry[name]
            if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
                continue
            if name not in read:
                read[name] = Material.from_trimesh(geom, f"meshes[{len(meshes)}]")
            v = trimesh.transform_points(np.asarray(geom.vertices, dtype=np.float64), transform)
            meshes.append((v, np.asarray(geom.faces)))
            materials.append(read[name])
        if not meshes:
            raise ValueError("obj: the trimesh scene has no triangle meshes")
        return cls(meshes=meshes, materials=materials)

    @staticmethod
    def _meshes(value: Any, name: str) -> list[Mesh]:
        if value is None:
            return []
        single = hasattr(value, "vertices") or (
            isinstance(value, tuple) and len(value) == 2 and hasattr(value[0], "shape")
        )
        if single:
            return [as_mesh(value, name)]
        if not isinstance(value, Iterable):
            raise TypeError(f"{name}: must be a mesh or a list of meshes, got {type(value).__name__}")
        return [as_mesh(m, f"{name}[{k}]") for k, m in enumerate(value)]

    @property
    def occluder_mesh(self) -> Mesh:
        """All occluders as one (vertices, faces) mesh."""
        return self._occ

    @property
    def receiver_mesh(self) -> Mesh:
        """All receivers as one (vertices, faces) mesh."""
        return self._rec

    @property
    def triangle_count(self) -> int:
        if not self.split:
            return len(self._occ[1])
        return len(self._occ[1]) + len(self._rec[1])

    def __repr__(self) -> str:
        if not self.split:
            return f"Scene({len(self.meshes)} meshes / {self.triangle_count} triangles)"
        return (
            f"Scene({len(self.occluders)} occluder meshes / {len(self._occ[1])} triangles, "
            f"{len(self.receivers)} receiver meshes / {len(self._rec[1])} triangles)"
        )
