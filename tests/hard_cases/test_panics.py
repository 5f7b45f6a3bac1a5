"""A Rust panic never aborts Python nor escapes as pyo3's PanicException (a
BaseException that `except Exception` misses): the bindings catch it and
raise RuntimeError, and the next call works. `_core._panic_for_tests`
panics on purpose, on the calling thread or in a rayon worker."""

import re
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import _core, scenes

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("in_worker", [False, True])
def test_a_panic_becomes_runtime_error_and_the_next_call_works(in_worker):
    scene, light = scenes.square_plate()
    before = ss.soft_shadow_map(scene, light, resolution=32).visibility
    for _ in range(3):
        with pytest.raises(RuntimeError, match="internal error.*deliberate panic"):
            _core._panic_for_tests(in_worker)
    # The thread pool and the module are intact: same answer, all methods.
    np.testing.assert_array_equal(ss.soft_shadow_map(scene, light, resolution=32).visibility, before)
    for method in ("bitmask", "exact"):
        assert ss.soft_shadow_map(scene, light, resolution=16, method=method, samples=16).visibility.min() == 0.0


def test_no_cargo_profile_aborts_on_panic():
    # panic = "abort" would make catch_unwind useless: a panic would kill the
    # Python process.
    text = (ROOT / "Cargo.toml").read_text()
    assert not re.search(r"^\s*panic\s*=\s*\"abort\"", text, re.M)
