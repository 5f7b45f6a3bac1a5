"""method="bitmask": micro-patches mark light samples in a mask per receiver."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import metrics, scenes

# Measured at 256² output, 128² occluder maps, two layers, 256 samples
# (errors of the published SSM on the same scenes: 0.031, 0.028, 0.037, 0.033).
BITMASK_ERRORS = {"bunny_floating": 0.0076, "bunny_on_floor": 0.0106, "two_spheres": 0.0077, "torus": 0.0081}


@pytest.mark.parametrize("name", sorted(BITMASK_ERRORS))
def test_bitmask_beats_the_published_method_against_mitsuba(reference_for, name):
    scene, light = scenes.SCENES[name]()
    base = ss.soft_shadow_map(scene, light, resolution=256)
    ref = reference_for(name, base, scene.occluders)
    bm = ss.soft_shadow_map(scene, light, resolution=256, occluder_resolution=128, method="bitmask", samples=256)
    err = metrics.shadow_error(bm.visibility, ref)
    ssm = metrics.shadow_error(base.visibility, ref)
    # Within 12% of the measured error, and at least 2.5x below the SSM's.
    assert err <= BITMASK_ERRORS[name] * 1.12, err
    assert err * 2.5 < ssm, (err, ssm)


def test_more_samples_and_finer_occluder_maps_help(reference_for):
    scene, light = scenes.bunny_floating()
    base = ss.soft_shadow_map(scene, light, resolution=128)
    ref = reference_for("bunny_floating", base, scene.occluders)
    err = {
        k: metrics.shadow_error(
            ss.soft_shadow_map(scene, light, resolution=128, method="bitmask", samples=k).visibility, ref
        )
        for k in (16, 64, 256)
    }
    assert err[16] > err[64] > err[256], err


def test_adding_an_occluder_never_brightens():
    light = scenes.default_light()
    floor = scenes.floor()
    a = scenes.quad((0.2, 2.0, 0.0), 0.3)
    b = scenes.quad((-0.2, 2.5, 0.1), 0.3)
    one = ss.soft_shadow_map(ss.Scene([a], [floor]), light, resolution=64, extent=0.6, method="bitmask")
    two = ss.soft_shadow_map(ss.Scene([a, b], [floor]), light, resolution=64, extent=0.6, method="bitmask")
    assert np.all(two.visibility <= one.visibility)
    assert (one.visibility - two.visibility).max() > 0.3


def test_bitmask_from_depth_and_points():
    scene, light = scenes.torus_floating()
    sm = ss.soft_shadow_map(scene, light, resolution=64, method="bitmask", samples=64)
    assert sm.occluder_depth is not None and sm.method.samples == 64
    again = ss.soft_shadow_map_from_depth(
        sm.occluder_depth,
        sm.receiver_depth,
        light_size=light.size,
        extent=sm.extent,
        occluder_depth_back=sm.occluder_depth_back,
        method="bitmask",
        samples=64,
    )
    np.testing.assert_array_equal(again.visibility, sm.visibility)
    pts, idx = sm.receiver_points()
    np.testing.assert_allclose(sm.sample(pts), sm.visibility.ravel()[idx], atol=1e-6)
    vis = sm.visibility
    assert vis.dtype == np.float32 and np.all((vis >= 0) & (vis <= 1))
    # Visibility is a count of samples: multiples of 1/64.
    np.testing.assert_allclose(vis * 64, np.round(vis * 64), atol=1e-4)


def test_bitmask_sample_counts():
    scene, light = scenes.square_plate()
    with pytest.raises(ValueError, match="samples.*16, 64, 256, 1024"):
        ss.soft_shadow_map(scene, light, resolution=8, method="bitmask", samples=100)
