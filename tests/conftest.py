"""Shared fixtures: Mitsuba references computed once and cached on disk.

References depend only on the scene, the light, the map's grid and the sample
count, so they are cached in `.cache/references/` (ignored by git) under a key
made of those inputs. Delete the folder to recompute.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np
import pytest

# Imported first so that the reference package points DRJIT_LIBLLVM_PATH at a
# usable libLLVM before any test module imports mitsuba or drjit (the only
# place the library is looked for); it never imports Mitsuba itself.
import softshadow.reference  # noqa: F401

CACHE = Path(__file__).resolve().parent.parent / ".cache" / "references"
REFERENCE_SAMPLES = 1024


def _key(*parts: object) -> str:
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(np.ascontiguousarray(p).tobytes())
        else:
            h.update(repr(p).encode())
    return h.hexdigest()[:24]


@pytest.fixture(scope="session")
def reference_for():
    """reference_for(name, shadow_map, occluders) -> (H, W) Mitsuba visibility."""
    reference = pytest.importorskip("softshadow.reference")
    pytest.importorskip("mitsuba")
    CACHE.mkdir(parents=True, exist_ok=True)

    def get(name: str, sm, occluders, samples: int = REFERENCE_SAMPLES) -> np.ndarray:
        key = _key(name, sm.light, sm.extent, sm.receiver_depth, samples, [m[0] for m in occluders])
        path = CACHE / f"{name}-{key}.npy"
        if path.exists():
            return np.load(path)
        ref = reference.reference_map(sm, occluders, samples=samples)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npy")
        np.save(tmp, ref)
        tmp.replace(path)
        return ref

    return get
