"""Fixtures over every backend and method (see common.py)."""

import os

import pytest

import softshadow as ss
from hard_cases.common import BACKENDS, MAP_METHODS, METHODS


@pytest.fixture(params=BACKENDS)
def backend(request):
    # The GPU joins where an adapter opens (lavapipe in CI, where
    # SOFTSHADOW_REQUIRE_GPU=1 makes a missing one a failure).
    if request.param == "gpu" and not ss.gpu_available():
        if os.environ.get("SOFTSHADOW_REQUIRE_GPU") == "1":
            pytest.fail("SOFTSHADOW_REQUIRE_GPU=1 but no GPU adapter opens")
        pytest.skip("no GPU adapter")
    return request.param


@pytest.fixture(params=METHODS)
def method(request):
    return request.param


@pytest.fixture(params=MAP_METHODS)
def map_method(request):
    return request.param
