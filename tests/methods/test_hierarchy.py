"""The occluder hierarchy (``hierarchy=``) and ``method="auto"``."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import metrics, scenes


@pytest.mark.parametrize("name", ["bunny_floating", "two_spheres"])
def test_the_hierarchy_changes_less_than_the_error_it_saves_time_for(reference_for, name):
    # At 256² with 256² occluder maps the wide penumbrae read coarser levels
    # (1.2-4.4x faster at 512², see benchmarks/bench_hierarchy.py); the change
    # must stay well inside the method's own error against Mitsuba.
    scene, light = scenes.SCENES[name]()
    kw = dict(resolution=256, method="bitmask", samples=256)
    full = ss.soft_shadow_map(scene, light, hierarchy=False, **kw)
    fast = ss.soft_shadow_map(scene, light, **kw)
    assert fast.method.hierarchy is True and full.method.hierarchy is False
    ref = reference_for(name, ss.soft_shadow_map(scene, light, resolution=256), scene.occluders)
    err_full = metrics.shadow_error(full.visibility, ref)
    err_fast = metrics.shadow_error(fast.visibility, ref)
    change = np.abs(fast.visibility - full.visibility)
    assert change.max() > 0.0, "the hierarchy never left level 0"
    assert change.mean() <= 0.25 * err_full, (change.mean(), err_full)
    assert err_fast <= err_full + 0.0015, (err_fast, err_full)


def test_the_hierarchy_keeps_contact_shadows_sharp(reference_for):
    # The bunny sits on the floor: near the contact the nearest occluder is
    # at the receiver (d -> 0), so those tiles must keep the finest level.
    scene, light = scenes.bunny_on_floor()
    kw = dict(resolution=256, method="bitmask", samples=256)
    full = ss.soft_shadow_map(scene, light, hierarchy=False, **kw)
    fast = ss.soft_shadow_map(scene, light, **kw)
    near_contact = full.occluder_depth_back - full.receiver_depth > -0.05
    near_contact &= np.isfinite(full.receiver_depth)
    assert near_contact.sum() > 100
    assert np.abs(fast.visibility - full.visibility)[near_contact].max() < 1e-6


def test_ssm_is_published_without_a_hierarchy_unless_asked():
    scene, light = scenes.torus_floating()
    paper = ss.soft_shadow_map(scene, light, resolution=128)
    assert paper.method.hierarchy is False
    asked = ss.soft_shadow_map(scene, light, resolution=128, hierarchy=True)
    assert asked.method.hierarchy is True
    assert np.all((asked.visibility >= 0) & (asked.visibility <= 1))
    exact = ss.soft_shadow_map(scene, light, resolution=64, method="exact", samples=16)
    assert not hasattr(exact.method, "hierarchy")


def test_hierarchy_is_refused_where_it_does_not_apply():
    scene, light = scenes.torus_floating()
    with pytest.raises(ValueError, match="hierarchy: applies to the occluder-map methods"):
        ss.soft_shadow_map(scene, light, resolution=32, method="exact", hierarchy=True)
    with pytest.raises(TypeError, match="hierarchy: must be a bool"):
        ss.soft_shadow_map(scene, light, resolution=32, hierarchy="yes")


@pytest.mark.parametrize(
    "resolution, occluders",
    [
        ((256, 256), (64, 64)),
        ((128, 128), (64, 64)),
        ((48, 48), (48, 48)),
        ((300, 100), (75, 64)),
        ((1024, 512), (256, 128)),
    ],
)
def test_auto_rule(resolution, occluders):
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=resolution, method="auto")
    assert sm.method == ss.Ssm(passes=2, occluder_resolution=occluders, hierarchy=False, precision="f32")
    assert ss.Auto().rule(resolution) == ss.Ssm(passes=2, occluder_resolution=occluders)
    assert sm.occluder_depth.shape == occluders[::-1]


def test_auto_runs_the_rule_and_names_what_ran():
    scene, light = scenes.bunny_floating()
    auto = ss.soft_shadow_map(scene, light, resolution=256, method="auto")
    same = ss.soft_shadow_map(scene, light, resolution=256, method="ssm", occluder_resolution=64)
    assert auto.method == same.method == ss.Ssm(passes=2, occluder_resolution=64, hierarchy=False)
    assert ss.soft_shadow_map(scene, light, resolution=256, method=ss.Auto()).method == auto.method
    assert auto.occluder_depth.shape == (64, 64)
    np.testing.assert_array_equal(auto.visibility, same.visibility)
    # An explicit occluder resolution wins over the rule.
    mine = ss.soft_shadow_map(scene, light, resolution=128, method="auto", occluder_resolution=96)
    assert mine.occluder_depth.shape == (96, 96)
    # From depth maps the occluder maps are the caller's.
    fd = ss.soft_shadow_map_from_depth(
        same.occluder_depth, same.receiver_depth, light_size=1.0, extent=same.extent, method="auto"
    )
    assert fd.method == ss.Ssm(passes=1, occluder_resolution=64, hierarchy=False)
