"""Receivers seen at grazing angles, and maps as wide as tan = 50.

Both stretch a texel's footprint on the receiver over many world units and
make its depth change fast across the map, which 1/Z interpolation and the
kernels' f32 tangents must survive. References: `exact` with 4096 samples
(itself checked against Mitsuba in test_against_mitsuba.py / test_exact.py).
"""

import numpy as np
import pytest

import softshadow as ss
from hard_cases.common import assert_visibility, options
from hard_cases.meshes import box
from softshadow import scenes

# Mean |V - V_exact| over the shadow. Measured: grazing at 20 / 150 and the
# tan-50 map: ssm 0.019 / 0.0043 / 0.020, bitmask 0.017 / 0.0047 / 0.020,
# exact (256 samples) 0.0011 everywhere, pcss 0.017 / 0.0069 / 0.020 -- the
# methods' usual errors (README); smoothies 0.055 / 0.056 / 0.042 (a fake
# outer penumbra on a hard umbra).
BOUND = {"ssm": 0.03, "bitmask": 0.03, "exact": 0.003, "smoothies": 0.07, "pcss": 0.03}


def _check(sm, ref, method):
    assert_visibility(sm.visibility)
    shadow = ref < 1 - 1e-3
    assert shadow.sum() >= 20, "the test needs a shadow"
    err = np.abs(sm.visibility - ref)[shadow].mean()
    assert err <= BOUND[method], err
    return err


def _grazing_scene(distance):
    # The light at height 4 aims at a floor point `distance` away: its rays
    # meet the floor at atan(4 / distance) (1.5 degrees at 150). A box 2 wide
    # and 1 tall stands before that point.
    light = ss.RectLight(center=(0, 4, 0), normal=(distance, -4, 0), up=(0, 1, 0), size=(1.0, 1.0))
    occ = box((distance - 12.0, 0.0, -1.0), (distance - 10.0, 1.0, 1.0))
    floor = scenes.quad((distance, 0.0, 0.0), 40.0)
    return ss.Scene(occluders=[occ], receivers=[floor]), light


@pytest.mark.parametrize("distance", [20.0, 150.0])
def test_grazing_receiver(method, backend, distance):
    scene, light = _grazing_scene(distance)
    kw = dict(resolution=64)
    sm = ss.soft_shadow_map(scene, light, **kw, **options(method, backend, passes=2))
    ref = ss.soft_shadow_map(scene, light, **kw, extent=sm.extent, method="exact", samples=4096).visibility
    _check(sm, ref, method)
    # The receiver depth spans a wide range across the map (grazing).
    d = sm.receiver_depth[np.isfinite(sm.receiver_depth)]
    assert d.max() / d.min() > 1.3


def test_wide_extent_tan_50(method, backend):
    # Light looking straight down over a floor 800 wide; a plate at tangent
    # x = 45 (90 away, 2 below the light) shadows the floor near tangent 46.
    light = scenes.default_light()
    occ = scenes.quad((-90.0, 2.0, 0.0), 2.0)  # u = -x: tangent +45
    floor = scenes.quad((0.0, 0.0, 0.0), 400.0)
    scene = ss.Scene(occluders=[occ], receivers=[floor])
    kw = dict(resolution=(1024, 16), extent=(50.0, 2.0))
    sm = ss.soft_shadow_map(scene, light, **kw, **options(method, backend, passes=2))
    ref = ss.soft_shadow_map(scene, light, **kw, method="exact", samples=4096).visibility
    _check(sm, ref, method)
    # The shadow is where the closed form puts it: tangent 45 +- 1 at depth
    # 2 projects onto the floor (depth 4) around tangent 45, umbra inside.
    x = (-1 + 2 * (np.arange(1024) + 0.5) / 1024) * 50.0
    umbra = np.abs(x - 45.0) < 0.5
    assert sm.visibility[8, umbra].max() <= 0.05
    assert sm.visibility[8, np.abs(x) < 40].min() == 1.0


def test_widest_extent_accepted_and_beyond_refused(map_method, backend):
    occ = np.full((4, 4), np.inf, np.float32)
    occ[1:3, 1:3] = 2.0
    rec = np.full((4, 4), 4.0, np.float32)
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=1.0, extent=1e6, **options(map_method, backend))
    assert_visibility(v.visibility)
    # Texels 5e5 wide in tangent: the plate's back-projection covers the
    # light from every receiver under it.
    np.testing.assert_array_equal(v.visibility, np.where(np.isfinite(occ), 0.0, 1.0))
    with pytest.raises(ValueError, match=r"extent: .*<= 1e6"):
        ss.soft_shadow_map_from_depth(occ, rec, light_size=1.0, extent=(1.0, 2e6))
