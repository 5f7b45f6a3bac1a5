"""Mitsuba reference maps cached on disk.

A reference depends only on the scene's occluders, the light, the map's grid
(its extent and receiver depth) and the sample count, so it is stored under a
key hashed from those inputs and computed once; the tests, the study and the
benchmarks share the cache (``.cache/references/`` of the checkout, ignored by
git). Delete the folder to recompute. Files are written to a temporary name
and renamed, so a killed run never leaves half a file behind.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

import numpy as np

from .visibility import reference_map


def key(*parts: object) -> str:
    """A short hash of arrays (their bytes) and other values (their repr)."""
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(np.ascontiguousarray(p).tobytes())
        else:
            h.update(repr(p).encode())
    return h.hexdigest()[:24]


def cached_reference_map(
    name: str, sm: Any, occluders: list[Any], *, samples: int, cache: Path, seed: int = 0
) -> np.ndarray:
    """``reference_map(sm, occluders, samples=samples, seed=seed)``, from
    ``cache`` when it holds one for the same inputs; ``name`` labels the file.
    A second seed measures the reference's own noise."""
    parts: list[object] = [name, sm.light, sm.extent, sm.receiver_depth, samples, [m[0] for m in occluders]]
    if seed:
        parts.append(("seed", seed))  # seed 0 keeps the keys it always had
    path = cache / f"{name}-{key(*parts)}.npy"
    if path.exists():
        return np.load(path)
    ref = reference_map(sm, occluders, samples=samples, seed=seed)
    cache.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npy")
    np.save(tmp, ref)
    tmp.replace(path)
    return ref


def cached_reference_image(
    name: str, scene: Any, light: Any, camera: Any, *, samples: int, cache: Path, seed: int = 0
) -> Any:
    """``render_visibility(scene, light, camera, samples, seed=seed)`` (a
    :class:`softshadow.reference.ReferenceImage`), from ``cache`` when it
    holds one for the same meshes, light, camera, samples and seed; ``name``
    labels the file. The cached image keeps the timings of the run that
    made it."""
    from .eye import ReferenceImage, _scene_meshes, render_visibility

    meshes = [part for _, v, f in _scene_meshes(scene) for part in (v, f)]
    parts: list[object] = [name, repr(light), repr(camera), samples, seed, *meshes]
    path = cache / f"eye-{name}-{key(*parts)}.npz"
    fields = ("visibility", "mask", "depth", "position", "normal", "mesh_id")
    scalars = ("samples", "time_first_hits", "time_shadow", "rays")
    if path.exists():
        with np.load(path) as data:
            return ReferenceImage(
                **{f: data[f] for f in fields},
                samples=int(data["samples"]),
                time_first_hits=float(data["time_first_hits"]),
                time_shadow=float(data["time_shadow"]),
                rays=int(data["rays"]),
            )
    ref = render_visibility(scene, light, camera, samples, seed=seed)
    cache.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
    np.savez_compressed(tmp, **{f: getattr(ref, f) for f in fields + scalars})
    tmp.replace(path)
    return ref
