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


def test_lights_are_the_core_s_frozen_comparable_picklable_classes():
    import copy
    import pickle

    from softshadow import _core

    assert ss.RectLight is _core.RectLight and ss.DirectionalLight is _core.DirectionalLight
    rect = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 2), radiance=(1, 2, 3))
    sun = ss.DirectionalLight(direction=(0.3, -1, 0.2), up=(0, 0, 1), angular_size=2.0, irradiance=0.5)
    for light in (rect, sun):
        for back in (pickle.loads(pickle.dumps(light)), copy.deepcopy(light), eval(repr(light), vars(ss))):
            assert back == light and hash(back) == hash(light) and back is not light
            np.testing.assert_array_equal(back.n, light.n)
        with pytest.raises(AttributeError):
            light.up = (1, 0, 0)  # type: ignore[misc]
    assert rect != ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 2))
    assert rect.radiance == (1.0, 2.0, 3.0) and sun.irradiance == (0.5, 0.5, 0.5)
    assert sun.angular_size == (2.0, 2.0) and rect != sun
    assert repr(rect) == (
        "RectLight(center=(0.0, 4.0, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), "
        "size=(1.0, 2.0), radiance=(1.0, 2.0, 3.0))"
    )
    # The frame is a fresh array each time: changing one changes nothing.
    rect.n[0] = 7.0
    assert rect.n[0] == 0.0
