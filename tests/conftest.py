"""Shared fixtures: Mitsuba references computed once and cached on disk; and
the markers every test gets from what it uses.

References depend only on the scene, the light, the map's grid and the sample
count, so they are cached in `.cache/references/` (ignored by git) under a key
made of those inputs. Delete the folder to recompute.

Markers (registered in pyproject.toml, `--strict-markers`), set here at
collection so that no test has to remember them:

* ``gpu``: the test runs on the GPU backend, so it needs an adapter: it uses
  the ``gpu`` fixture or is parametrized with ``backend="gpu"`` (the
  fixture or argument named ``backend``); marked by hand where the backend
  comes from elsewhere (hypothesis draws it in hard_cases/test_properties.py).
  A test that only checks a refusal of ``backend="gpu"`` (it passes with
  ``SOFTSHADOW_GPU=off``) is not one.
* ``mitsuba``: the test renders with Mitsuba: it, its module (at module
  level) or a fixture it uses, directly or through other fixtures, calls
  ``pytest.importorskip("mitsuba")`` (or ``"drjit"``), as every use of
  Mitsuba in the tests does (``reference_for`` among them).
* ``slow`` is set by hand (``@pytest.mark.slow``, or ``pytest.param(...,
  marks=...)``) on tests measured above ~5 s on 2 cores; here only for
  :data:`SLOW_ELSEWHERE`, tests whose files are not edited for it.
  ``-m "not slow"`` leaves them out.
"""

from __future__ import annotations

import ast
import functools
import inspect
import os
import textwrap
from pathlib import Path
from typing import Any

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


# --------------------------------------------------------------------------
# Markers from what a test uses
# --------------------------------------------------------------------------

MITSUBA_MODULES = {"mitsuba", "drjit"}
#: Slow tests (node ids, from the tests folder) in files kept as they are:
#: tests/golden/ is recorded before a refactor and not touched by one.
SLOW_ELSEWHERE = {"golden/test_golden.py::test_every_golden_case_gives_the_recorded_bits"}


def _skips_without_mitsuba(node: ast.AST, top_level_only: bool) -> bool:
    """Whether ``node`` calls ``importorskip("mitsuba")`` (or drjit); with
    ``top_level_only``, not counting calls inside functions or classes."""
    stack = [node]
    while stack:
        n = stack.pop()
        if (
            isinstance(n, ast.Call)
            and (getattr(n.func, "attr", None) or getattr(n.func, "id", None)) == "importorskip"
            and n.args
            and isinstance(n.args[0], ast.Constant)
            and n.args[0].value in MITSUBA_MODULES
        ):
            return True
        for child in ast.iter_child_nodes(n):
            if top_level_only and isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                continue
            stack.append(child)
    return False


@functools.cache
def _source_needs_mitsuba(obj: Any, top_level_only: bool = False) -> bool:
    try:
        source = textwrap.dedent(inspect.getsource(obj))
    except (OSError, TypeError):
        return False
    return _skips_without_mitsuba(ast.parse(source), top_level_only)


def _needs_mitsuba(item: pytest.Item) -> bool:
    module = getattr(item, "module", None)
    if module is not None and _source_needs_mitsuba(module, top_level_only=True):
        return True
    function = getattr(item, "function", None)
    if function is not None and _source_needs_mitsuba(function):
        return True
    # Every fixture the test uses, through other fixtures too (its closure).
    info = getattr(item, "_fixtureinfo", None)
    for defs in getattr(info, "name2fixturedefs", {}).values():
        if any(_source_needs_mitsuba(d.func) for d in defs):
            return True
    return False


def _runs_on_the_gpu(item: pytest.Item) -> bool:
    callspec = getattr(item, "callspec", None)
    params = callspec.params if callspec is not None else {}
    return "gpu" in getattr(item, "fixturenames", ()) or params.get("backend") == "gpu"


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if _runs_on_the_gpu(item):
            item.add_marker(pytest.mark.gpu)
        if _needs_mitsuba(item):
            item.add_marker(pytest.mark.mitsuba)
        if any(item.nodeid.endswith(node) for node in SLOW_ELSEWHERE):
            item.add_marker(pytest.mark.slow)
