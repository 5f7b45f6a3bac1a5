"""The same scenes give the same bits: every golden case (every method and
option, both entry points, `ShadowMap.sample`, a point light; see cases.py)
hashed by `make_golden.py` before a refactor, asserted after it.

GPU hashes are checked only on the adapter that recorded them (lavapipe in
CI): another driver may round differently where the GPU tests allow it.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import softshadow as ss

from .cases import GPU_ADAPTER_KEY, cases, digest

GOLDEN = json.loads((Path(__file__).resolve().parent / "hashes.json").read_text())


def _backends() -> list[str]:
    out = ["cpu"]
    if ss.gpu_available() and GPU_ADAPTER_KEY() == GOLDEN["gpu_adapter"]:
        out.append("gpu")
    return out


def test_every_golden_case_gives_the_recorded_bits():
    ran, changed = 0, []
    backends = _backends()
    for key, run in cases(backends):
        ran += 1
        if digest(run()) != GOLDEN["hashes"][key]:
            changed.append(key)
    assert not changed, f"{len(changed)} of {ran} cases changed: {changed[:20]}"
    expected = sum(1 for k in GOLDEN["hashes"] if k.rsplit("/", 1)[1] in backends)
    assert ran == expected


def test_the_golden_file_covers_both_backends():
    keys = GOLDEN["hashes"]
    if "gpu" not in _backends():
        pytest.skip("the GPU hashes were recorded on another adapter")
    assert any(k.endswith("/gpu") for k in keys) and any(k.endswith("/cpu") for k in keys)
