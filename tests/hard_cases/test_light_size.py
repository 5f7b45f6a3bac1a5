"""Point-light limit (size -> 0, and exactly 0) and lights far larger than the scene.

As the light shrinks the penumbra's tangent half-width (L/2)(1/z_O - 1/z_R)
falls below half a texel and every method returns the hard shadow map: 0
where the occluder covers the receiver's direction, 1 elsewhere. A size of
exactly (0, 0) is a point light and gives that map; sizes between 0 and
1e-30 of the receivers' depth, which f32 cannot resolve, are refused
(units.rs).
"""

import numpy as np
import pytest

import softshadow as ss
from hard_cases import plate
from hard_cases.common import assert_visibility, options, samples_points
from softshadow import scenes

EXT = (0.5, 0.5)
RECT = (-0.25, 0.25, -0.25, 0.25)


@pytest.mark.parametrize("size", [1e-2, 1e-4, 1e-6, 1e-20])
def test_small_lights_converge_to_the_hard_shadow_from_depth(map_method, backend, size):
    occ, rec, x, y = plate.maps(64, 64, EXT, RECT, 2.0, 4.0)
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=size, extent=EXT, **options(map_method, backend)).visibility
    assert_visibility(v)
    want = plate.visibility(x[None, :], y[:, None], RECT, 2.0, 4.0, size, size)
    assert np.abs(v - want).max() <= plate.bound(map_method)
    if size <= 1e-4:  # penumbra half-width 2.5e-5 tangent << half a texel (7.8e-3)
        np.testing.assert_allclose(v, np.where(np.isfinite(occ), 0.0, 1.0), atol=1e-6)


@pytest.mark.parametrize("size", [1e-4, 1e-9])
def test_small_lights_converge_to_the_hard_shadow_from_meshes(method, backend, size):
    # Plate of half-size 0.5 at height 2 (depth 2): tangent half-size 0.25,
    # on texel edges of a 64² map over extent 0.5.
    scene, light = scenes.square_plate(light_size=size)
    sm = ss.soft_shadow_map(scene, light, resolution=64, extent=EXT, **options(method, backend))
    x = plate.centers(64, 0.5)
    hard = (np.abs(x) < 0.25)[None, :] & (np.abs(x) < 0.25)[:, None]
    np.testing.assert_allclose(sm.visibility, np.where(hard, 0.0, 1.0), atol=1e-6)


def test_point_light_of_size_zero_gives_the_hard_shadow(method, backend):
    # Size (0, 0) is a point light: the map methods take the hard shadow they
    # converge to (point_light.rs; their kernels divide by the size), exact
    # sends every ray to the light's center. Same maps as a 1e-9 light.
    scene, _ = scenes.square_plate()
    point = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=0.0)
    tiny = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=1e-9)
    kw = dict(resolution=64, extent=EXT, **options(method, backend))
    if backend == "gpu":
        # No GPU kernel for it: refused by name, never run on the CPU behind
        # the user's back.
        with pytest.raises(ValueError, match=r"size: a point light \(size 0\) runs on the CPU backend only"):
            ss.soft_shadow_map(scene, point, **kw)
        return
    sm = ss.soft_shadow_map(scene, point, **kw)
    x = plate.centers(64, 0.5)
    hard = (np.abs(x) < 0.25)[None, :] & (np.abs(x) < 0.25)[:, None]
    np.testing.assert_array_equal(sm.visibility, np.where(hard, 0.0, 1.0))
    np.testing.assert_allclose(sm.visibility, ss.soft_shadow_map(scene, tiny, **kw).visibility, atol=1e-6)
    pts, idx = sm.receiver_points()
    if not samples_points(method):
        with pytest.raises(ValueError, match="^method: "):
            sm.sample(pts)
        return
    np.testing.assert_array_equal(sm.sample(pts), sm.visibility.ravel()[idx])


def test_point_light_from_depth_maps(map_method, backend):
    occ, rec, _, _ = plate.maps(64, 64, EXT, RECT, 2.0, 4.0)
    occ[0, 0] = 5.0  # behind the receiver: no shadow
    if backend == "gpu":
        with pytest.raises(ValueError, match=r"light_size: a point light \(size 0\) runs on the CPU backend only"):
            ss.soft_shadow_map_from_depth(occ, rec, light_size=0.0, extent=EXT, **options(map_method, backend))
        return
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=0.0, extent=EXT, **options(map_method, backend))
    np.testing.assert_array_equal(v.visibility, np.where(occ < rec, 0.0, 1.0))


@pytest.mark.parametrize("size", [(0.0, 1.0), (-0.0, -1.0)])
def test_half_point_lights_are_refused(size):
    with pytest.raises(ValueError, match="size.*point light"):
        ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=size)
    occ, rec, _, _ = plate.maps(8, 8, EXT, RECT, 2.0, 4.0)
    with pytest.raises(ValueError, match="light_size"):
        ss.soft_shadow_map_from_depth(occ, rec, light_size=size, extent=EXT)


def test_size_below_what_f32_resolves_is_refused_by_name():
    # 1e-35 of the receivers' depth: 2/L leaves f32 (units.rs); the message
    # says so and points at the hard-shadow limit instead.
    occ, rec, _, _ = plate.maps(8, 8, EXT, RECT, 2.0, 4.0)
    with pytest.raises(ValueError, match="light_size.*f32"):
        ss.soft_shadow_map_from_depth(occ, rec, light_size=1e-35, extent=EXT)
    scene, _ = scenes.square_plate()
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=1e-35)
    with pytest.raises(ValueError, match="size.*f32"):
        ss.soft_shadow_map(scene, light, resolution=8, extent=EXT)


@pytest.mark.parametrize("size", [50.0, 1e3, 1e6])
def test_lights_far_larger_than_the_scene(map_method, backend, size):
    # The plate's back-projection (side 2 k a = 2) is a sliver of the light:
    # V = 1 - (2 / size)^2 under it, and the closed form everywhere.
    occ, rec, x, y = plate.maps(64, 64, EXT, RECT, 2.0, 4.0)
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=size, extent=EXT, **options(map_method, backend)).visibility
    assert_visibility(v)
    want = plate.visibility(x[None, :], y[:, None], RECT, 2.0, 4.0, size, size)
    if map_method == "ssm":
        assert np.abs(v - want).max() <= plate.SSM_BOUND
    else:
        # The bitmask resolves 1/256 of the light: a sliver of (2/size)^2
        # covers fewer samples than one stratum: all or nothing per sample.
        assert np.abs(v - want).max() <= max(plate.BITMASK_BOUND, (2 / size) ** 2 + 1 / 256)


def test_huge_light_from_meshes_follows_the_closed_form(method, backend):
    scene, light = scenes.square_plate(light_size=50.0)
    sm = ss.soft_shadow_map(scene, light, resolution=32, **options(method, backend))
    assert_visibility(sm.visibility)
    x = plate.centers(32, sm.extent[0])
    y = plate.centers(32, sm.extent[1])[::-1]
    want = plate.visibility(x[None, :], y[:, None], RECT, 2.0, 4.0, 50.0, 50.0)
    # Closed-form minimum: 1 - (2/50)^2 = 0.9984 under the plate.
    assert abs(float(want.min()) - (1 - (2 / 50) ** 2)) < 1e-9
    if method == "smoothies":
        # Fake soft shadows (Chan & Durand §2.1, §5): the umbra is the hard
        # shadow's, whatever the light's size, and the smoothies only darken
        # around it.
        hard = plate.visibility(x[None, :], y[:, None], RECT, 2.0, 4.0, 1e-9, 1e-9) < 0.5
        np.testing.assert_array_equal(sm.visibility <= 1e-6, hard)
        assert hard.sum() > 20 and sm.visibility[~hard].min() > 0.0
        return
    # exact: the back-projection (0.04 of the light's side) meets at most 2 x 2
    # of its 16 x 16 strata, so at most 4 of 256 samples are wrong.
    # pcss: one plate at one depth, its filter box the back-projection
    # (measured 2.7e-8).
    tol = {"ssm": 1e-4, "bitmask": 0.01, "exact": 4 / 256, "pcss": 1e-6}[method]
    assert np.abs(sm.visibility - want).max() <= tol
