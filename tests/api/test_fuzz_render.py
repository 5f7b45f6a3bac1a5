"""A brief run of the eye-view fuzzer (benchmarks/fuzz_render.py): about 15 s
of drawn calls of `softshadow.render` and `soft_shadow_map` from meshes, a
fixed seed, each call either a right result or a refusal naming an argument.
The long run (`--minutes 10`) is docs/development.md's."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

pytest.importorskip("trimesh")

HARNESS = Path(__file__).resolve().parents[2] / "benchmarks" / "fuzz_render.py"


def _harness():
    spec = importlib.util.spec_from_file_location("fuzz_render", HARNESS)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_a_brief_fuzz_of_the_eye_view_finds_no_failure(capsys):
    fuzz = _harness()
    # The calls run in a watched worker process: a crash or a hang (over
    # 100 s) is a failure with its reproducer, not a dead or stuck pytest.
    status = fuzz.main(["--seconds", "15", "--seed", "20240601", "--hang", "100"])
    out = capsys.readouterr().out
    assert "render ok" in out, out  # the calls reached the kernels
    assert status == 0, out
