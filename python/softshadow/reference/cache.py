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
