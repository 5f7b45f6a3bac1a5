"""A receiver nearer the light than the occluder is not shadowed by it."""

import numpy as np

import softshadow as ss
from hard_cases.common import assert_visibility, options
from softshadow import scenes


def test_receiver_above_the_occluder_is_lit(method, backend):
    # Receiver 1 below the light, occluder plate 3 below it: nothing between
    # the receiver and the light.
    light = scenes.default_light()
    scene = ss.Scene(occluders=[scenes.quad((0.0, 1.0, 0.0), 1.0)], receivers=[scenes.quad((0.0, 3.0, 0.0), 2.0)])
    sm = ss.soft_shadow_map(scene, light, resolution=32, extent=0.5, **options(method, backend))
    np.testing.assert_array_equal(sm.visibility, 1.0)


def test_receivers_on_both_sides_of_an_occluder(method, backend):
    # Two receiver strips, one above the plate (lit) and one below (shadowed).
    light = scenes.default_light()
    above = scenes.quad((-1.0, 3.0, 0.0), 0.5)  # depth 1, left half of the map
    below = scenes.quad((1.5, 0.0, 0.0), 1.0)  # depth 4, right half
    plate = scenes.quad((0.0, 2.0, 0.0), 1.5)  # depth 2, covers both
    scene = ss.Scene(occluders=[plate], receivers=[above, below])
    sm = ss.soft_shadow_map(scene, light, resolution=64, extent=1.0, **options(method, backend))
    assert_visibility(sm.visibility)
    near = sm.receiver_depth < 2.0
    far = np.isfinite(sm.receiver_depth) & (sm.receiver_depth > 2.0)
    assert near.any() and far.any()
    np.testing.assert_array_equal(sm.visibility[near], 1.0)
    # Below the plate, away from its edge (tangent 0.75 at depth 2), umbra.
    x = (np.arange(64) + 0.5) / 32 - 1.0
    inner = far & (np.abs(x) < 0.6)[None, :]
    assert inner.any() and sm.visibility[inner].max() <= 1e-6
