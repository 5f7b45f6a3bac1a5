"""Fixtures over every backend and method (see common.py)."""

import pytest

from hard_cases.common import BACKENDS, MAP_METHODS, METHODS


@pytest.fixture(params=BACKENDS)
def backend(request):
    return request.param


@pytest.fixture(params=METHODS)
def method(request):
    return request.param


@pytest.fixture(params=MAP_METHODS)
def map_method(request):
    return request.param
