"""Shared fixtures: Mitsuba references computed once and cached on disk.

References depend only on the scene, the light, the map's grid and the sample
count, so they are cached in `.cache/references/` (ignored by git) under a key
made of those inputs. Delete the folder to recompute.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

# Imported first so that the reference package points DRJIT_LIBLLVM_PATH at a
# usable libLLVM before any test module imports mitsuba or drjit (the only
# place the library is looked for); it never imports Mitsuba itself.
import softshadow as ss
import softshadow.reference  # noqa: F401
from softshadow.reference.cache import cached_reference_map

CACHE = Path(__file__).resolve().parent.parent / ".cache" / "references"
REFERENCE_SAMPLES = 1024


@pytest.fixture(scope="session")
def reference_for():
    """reference_for(name, shadow_map, occluders) -> (H, W) Mitsuba visibility."""
    pytest.importorskip("mitsuba")

    def get(name: str, sm, occluders, samples: int = REFERENCE_SAMPLES) -> np.ndarray:
        return cached_reference_map(name, sm, occluders, samples=samples, cache=CACHE)

    return get


@pytest.fixture(scope="session")
def gpu():
    """gpu_info() of the adapter the GPU tests run on; skips without one,
    fails instead when SOFTSHADOW_REQUIRE_GPU=1 (scripts/test.sh sets it)."""
    if not ss.gpu_available():
        if os.environ.get("SOFTSHADOW_REQUIRE_GPU") == "1":
            pytest.fail("SOFTSHADOW_REQUIRE_GPU=1 but no GPU adapter opens (is mesa-vulkan-drivers installed?)")
        pytest.skip("no GPU adapter")
    return ss.gpu_info()
