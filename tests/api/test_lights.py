"""The light frame and its validation."""

import numpy as np
import pytest

import softshadow as ss


def test_frame_follows_the_documented_convention():
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -2, 0), up=(0, 0.5, 3), size=(1.0, 2.0))
    np.testing.assert_allclose(light.n, [0, -1, 0])
    np.testing.assert_allclose(light.v, [0, 0, 1])
    # u = n x v
    np.testing.assert_allclose(light.u, np.cross(light.n, light.v))
    np.testing.assert_allclose(light.u, [-1, 0, 0])
    assert light.area == 2.0
    corners = light.corners()
    np.testing.assert_allclose(corners[2], [0, 4, 0] + 0.5 * light.u + 1.0 * light.v)


def test_scalar_size_means_a_square():
    assert ss.RectLight((0, 0, 0), (0, 0, 1), (0, 1, 0), size=0.5).size == (0.5, 0.5)


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(normal=(0, 0, 0)), ValueError, "normal"),
        (dict(up=(0, 0, 0)), ValueError, "up"),
        (dict(up=(0, -3, 0)), ValueError, "parallel"),
        (dict(size=(0.0, 1.0)), ValueError, "size"),
        (dict(size=(-1.0, 1.0)), ValueError, "size"),
        (dict(size=(1.0, float("inf"))), ValueError, "size"),
        (dict(center=(0, float("nan"), 0)), ValueError, "center"),
        (dict(center=(0, 1)), ValueError, "center"),
        (dict(center="abc"), TypeError, "center"),
    ],
)
def test_bad_lights_are_refused_with_the_argument_named(kwargs, exc, words):
    args = dict(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 1))
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.RectLight(**args)
