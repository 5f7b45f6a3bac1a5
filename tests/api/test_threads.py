"""Thread safety: many Python threads calling ``soft_shadow_map`` and
``render`` at once (the core releases the GIL, so they do run at once, sharing
the rayon pool, the block cache and, on the GPU, the one device) get the same
results, bit for bit, as the same calls made one after another.

GPU calls need an adapter (lavapipe in CI); see tests/gpu/test_gpu.py for the
SOFTSHADOW_REQUIRE_GPU rule.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes

THREADS = 8
ROUNDS = 3  # each call runs this many times in the pool, shuffled with the others


def light_view_calls(backend: str) -> list[tuple[str, Callable[[], Any]]]:
    bunny, bunny_light = scenes.bunny_floating()
    torus, torus_light = scenes.torus_floating()
    plate, plate_light = scenes.square_plate()
    size = 48 if backend == "gpu" else 96
    return [
        ("ssm bunny", lambda: ss.soft_shadow_map(bunny, bunny_light, resolution=size, backend=backend)),
        (
            "bitmask torus",
            lambda: ss.soft_shadow_map(torus, torus_light, resolution=size, method="bitmask", backend=backend),
        ),
        (
            "exact plate",
            lambda: ss.soft_shadow_map(
                plate, plate_light, resolution=size, method="exact", samples=64, backend=backend
            ),
        ),
        ("pcss bunny", lambda: ss.soft_shadow_map(bunny, bunny_light, resolution=size, method="pcss", backend=backend)),
        (
            "ssm torus, 1 thread",
            lambda: ss.soft_shadow_map(torus, torus_light, resolution=size, passes=1, backend=backend, threads=1),
        ),
    ]


def eye_view_calls(backend: str) -> list[tuple[str, Callable[[], Any]]]:
    res = (64, 48) if backend == "gpu" else (128, 96)
    bunny = scenes.eye_view.bunny_on_floor(res)
    torus = scenes.eye_view.torus_self(res)
    return [
        ("render ssm bunny", lambda: ss.render(*bunny, method="ssm", backend=backend)),
        ("render bitmask torus", lambda: ss.render(*torus, method="bitmask", backend=backend)),
        ("render exact bunny", lambda: ss.render(*bunny, method="exact", samples=16, backend=backend)),
        ("render shadow_mapping torus", lambda: ss.render(*torus, method="shadow_mapping", backend=backend)),
    ]


def arrays(result: Any) -> dict[str, np.ndarray]:
    """Every array a result holds, by name."""
    if isinstance(result, ss.ShadowMap):
        out = {"visibility": result.visibility, "receiver_depth": result.receiver_depth}
        if result.occluder_depth is not None:
            out["occluder_depth"] = result.occluder_depth
        if result.occluder_depth_back is not None:
            out["occluder_depth_back"] = result.occluder_depth_back
        return out
    out = {"visibility": result.visibility, "depth": result.depth, "position": result.position}
    out.update({f"shadow_maps[{k}]": m for k, m in enumerate(result.shadow_maps)})
    if hasattr(result, "shaded"):
        out["shaded"] = result.shaded
    return out


def assert_same_bits(a: dict[str, np.ndarray], b: dict[str, np.ndarray], name: str) -> None:
    assert a.keys() == b.keys(), name
    for k in a:
        assert a[k].dtype == b[k].dtype and a[k].shape == b[k].shape, f"{name}: {k}"
        # Bits, not values: NaN (no surface) and inf compare equal to themselves.
        assert a[k].tobytes() == b[k].tobytes(), f"{name}: {k} differs between serial and concurrent calls"


def run_concurrently(calls: list[tuple[str, Callable[[], Any]]]) -> dict[str, Any]:
    """Runs each call once serially, then ROUNDS times in the pool; returns
    the serial results by name."""
    first = {name: call() for name, call in calls}
    serial = {name: arrays(r) for name, r in first.items()}
    jobs = [c for c in calls for _ in range(ROUNDS)]
    random.Random(0).shuffle(jobs)
    with ThreadPoolExecutor(max_workers=THREADS) as pool:
        futures = [(name, pool.submit(call)) for name, call in jobs]
        results = [(name, f.result()) for name, f in futures]
    assert len(results) == len(calls) * ROUNDS
    for name, r in results:
        assert_same_bits(serial[name], arrays(r), name)
    return first


def test_concurrent_calls_on_the_cpu_match_serial_ones():
    first = run_concurrently(light_view_calls("cpu") + eye_view_calls("cpu"))
    assert {r.backend for r in first.values()} == {"cpu"}


@pytest.mark.slow
def test_concurrent_calls_on_the_gpu_match_serial_ones(gpu):
    first = run_concurrently(light_view_calls("gpu") + eye_view_calls("gpu"))
    # They ran on the device (no silent fallback to the CPU).
    assert {name: r.backend for name, r in first.items()} == dict.fromkeys(first, "gpu")
