"""Scale and position: results do not depend on the units or on where the
scene sits in the world.

Scaling every depth and the light's size by one factor moves no tangent, so
the visibility must not change. Before the kernels got depths in a unit near
the receivers' (units.rs), these tests failed: the SSM from depth maps at
2^50 (off by 2e-5: its 1e-36 guard on (1/z_O - 1/z_R)^2 starts to count),
2^60 and 2^90 (shadows gone) and at 2^-70, 2^-90 (the square overflows
f32); the ray caster at scene sizes 1e-15 and 1e15 (its f32 determinants
underflow or overflow). The bitmask passed. World -> light transforms are in
f64, so a scene and light moved together by 1e6 give the same maps.
"""

import numpy as np
import pytest

import softshadow as ss
from hard_cases import plate
from hard_cases.common import assert_visibility, options, samples_points
from hard_cases.meshes import moved
from softshadow import scenes

EXT = (0.5, 0.5)
RECT = (-0.3, 0.2, -0.15, 0.25)


@pytest.mark.parametrize("k", [-90, -70, -40, 20, 50, 60, 90])
def test_depth_maps_at_any_power_of_two_scale(map_method, backend, k):
    occ, rec, _, _ = plate.maps(40, 40, EXT, RECT, 2.0, 4.0)
    kw = dict(extent=EXT, **options(map_method, backend))
    base = ss.soft_shadow_map_from_depth(occ, rec, light_size=(1.0, 0.6), **kw).visibility
    s = 2.0**k
    scaled = ss.soft_shadow_map_from_depth(
        (occ * np.float32(s)).astype(np.float32),
        (rec * np.float32(s)).astype(np.float32),
        light_size=(s, 0.6 * s),
        **kw,
    ).visibility
    assert_visibility(scaled)
    assert base.min() <= 1e-6  # there is an umbra to lose
    np.testing.assert_array_equal(scaled, base)


def _scaled_scene(s):
    occ = scenes.sphere((0.1 * s, 2.0 * s, 0.0), 0.4 * s, n=24)
    floor = scenes.quad((0.0, 0.0, 0.0), 4.0 * s)
    light = ss.RectLight(center=(0, 4 * s, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1.0 * s, 0.7 * s))
    return ss.Scene(occluders=[occ], receivers=[floor]), light


@pytest.mark.parametrize("s", [1e-15, 1e-6, 1e6, 1e15])
def test_meshes_at_any_scale(method, backend, s):
    scene, light = _scaled_scene(1.0)
    kw = dict(resolution=48, **options(method, backend, passes=2))
    base = ss.soft_shadow_map(scene, light, **kw)
    scene_s, light_s = _scaled_scene(s)
    sm = ss.soft_shadow_map(scene_s, light_s, **kw)
    assert_visibility(sm.visibility)
    # There is an umbra to lose (pcss's filter box, from the sphere's mean
    # blocker depth, is a little wider than the true umbra: measured 0.0038).
    assert base.visibility.min() <= (0.01 if method == "pcss" else 1e-6)
    # Not powers of two: vertices round differently, which can move a
    # rasterized edge over a texel center or a ray past a triangle's edge.
    d = np.abs(sm.visibility - base.visibility)
    assert d.mean() <= 1e-3 and d.max() <= 0.1, (d.mean(), d.max())
    # Depth maps come back in the caller's units.
    np.testing.assert_allclose(sm.receiver_depth, base.receiver_depth * s, rtol=1e-6)


@pytest.mark.parametrize("offset", [(1e6, 1e6, 1e6), (-3e7, 2e6, 5e7)])
def test_scene_and_light_moved_far_from_the_origin(method, backend, offset):
    scene, light = scenes.two_spheres()
    kw = dict(resolution=48, **options(method, backend))
    base = ss.soft_shadow_map(scene, light, **kw)
    far_scene = ss.Scene(
        occluders=[moved(m, offset) for m in scene.occluders],
        receivers=[moved(m, offset) for m in scene.receivers],
    )
    far_light = ss.RectLight(center=np.add(light.center, offset), normal=light.normal, up=light.up, size=light.size)
    sm = ss.soft_shadow_map(far_scene, far_light, **kw)
    # f64 light space: coordinates move by rounding of 1e-10..1e-8, far below
    # the rasterizer's 1/256 texel snap and the kernels' f32.
    np.testing.assert_allclose(sm.extent, base.extent, rtol=1e-7)
    np.testing.assert_array_equal(np.isfinite(sm.receiver_depth), np.isfinite(base.receiver_depth))
    np.testing.assert_allclose(sm.receiver_depth, base.receiver_depth, rtol=1e-6)
    d = np.abs(sm.visibility - base.visibility)
    assert d.max() <= (1 / 256 if method == "exact" else 1e-5), d.max()
    # In f32 the same move would cost 4 units of precision at 5e7: this
    # scene would be gone. Sampling at far points works too.
    pts, idx = sm.receiver_points()
    if not samples_points(method):
        with pytest.raises(ValueError, match="^method: "):
            sm.sample(pts)
        return
    np.testing.assert_allclose(sm.sample(pts), sm.visibility.ravel()[idx], atol=1e-5)


def _huge_triangle(size):
    # A triangle at height 2 whose interior covers the light's axis.
    v = np.array([[size, 2.0, 0.0], [0.0, 2.0, size], [-size, 2.0, -size]])
    return ss.Scene(occluders=[(v, [[0, 1, 2]])], receivers=[scenes.floor()])


@pytest.mark.parametrize("size", [1e3, 1e9, 1e14])
def test_huge_triangles_keep_their_shape(method, backend, size):
    # The triangle covers the whole map: umbra wherever the penumbra reach
    # (0.125 in tangent) stays inside the map (the map methods see no occluder
    # beyond the map's edge, so receivers near it see past).
    sm = ss.soft_shadow_map(
        _huge_triangle(size), scenes.default_light(), resolution=16, extent=0.5, **options(method, backend)
    )
    assert_visibility(sm.visibility)
    assert sm.visibility[4:12, 4:12].max() <= 1e-6


def test_triangles_beyond_what_f64_clipping_resolves_are_refused(method, backend):
    # 1e19 wide: clipped in f64 to a map 1 wide its interior was lost (the
    # shadow vanished) and the ray caster's f32 determinants overflowed.
    with pytest.raises(ValueError, match=r"occluders: vertex 0 lies 1e19 from the light's axis"):
        ss.soft_shadow_map(
            _huge_triangle(1e19), scenes.default_light(), resolution=16, extent=0.5, **options(method, backend)
        )
