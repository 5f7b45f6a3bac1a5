"""The two entry points, the ShadowMap they return, and sampling at points."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes


@pytest.fixture(scope="module")
def bunny():
    return scenes.bunny_floating()


@pytest.mark.parametrize("passes", [1, 2])
def test_depth_entry_matches_mesh_entry(bunny, passes):
    scene, light = bunny
    sm = ss.soft_shadow_map(scene, light, resolution=(96, 80), passes=passes)
    again = ss.soft_shadow_map_from_depth(
        sm.occluder_depth,
        sm.receiver_depth,
        light_size=light.size,
        extent=sm.extent,
        occluder_depth_back=sm.occluder_depth_back,
    )
    np.testing.assert_array_equal(again.visibility, sm.visibility)
    assert again.passes == passes


@pytest.mark.parametrize("occ_res", [(48, 40), (200, 160)])
def test_occluder_maps_at_their_own_resolution(bunny, occ_res):
    scene, light = bunny
    sm = ss.soft_shadow_map(scene, light, resolution=(96, 80), occluder_resolution=occ_res)
    w, h = occ_res
    assert sm.visibility.shape == sm.receiver_depth.shape == (80, 96)
    assert sm.occluder_depth.shape == sm.occluder_depth_back.shape == (h, w)
    again = ss.soft_shadow_map_from_depth(
        sm.occluder_depth,
        sm.receiver_depth,
        light_size=light.size,
        extent=sm.extent,
        occluder_depth_back=sm.occluder_depth_back,
    )
    np.testing.assert_array_equal(again.visibility, sm.visibility)
    pts, idx = sm.receiver_points()
    np.testing.assert_allclose(sm.sample(pts), sm.visibility.ravel()[idx], atol=1e-5)
    # Close to the map with full-resolution occluders, not equal to it.
    full = ss.soft_shadow_map(scene, light, resolution=(96, 80)).visibility
    d = np.abs(sm.visibility - full)
    assert 0 < d.mean() < 0.03


def test_bad_occluder_resolution(bunny):
    scene, light = bunny
    with pytest.raises(ValueError, match="occluder_resolution"):
        ss.soft_shadow_map(scene, light, occluder_resolution=0)
    with pytest.raises(TypeError, match="occluder_resolution"):
        ss.soft_shadow_map(scene, light, occluder_resolution=1.5)
    with pytest.raises(ValueError, match="occluder_resolution.*exact"):
        ss.soft_shadow_map(scene, light, method="exact", occluder_resolution=64)


def test_shadow_map_contents(bunny):
    scene, light = bunny
    sm = ss.soft_shadow_map(scene, light, resolution=(64, 48))
    assert sm.visibility.shape == (48, 64) and sm.resolution == (64, 48)
    for a in (sm.visibility, sm.receiver_depth, sm.occluder_depth, sm.occluder_depth_back):
        assert a.dtype == np.float32 and a.shape == (48, 64) and a.flags.c_contiguous
    assert np.all((sm.visibility >= 0) & (sm.visibility <= 1))
    assert sm.visibility.min() < 0.05  # the bunny's umbra
    # The floor at y = 0 is 4 below the light: planar depth 4 everywhere.
    np.testing.assert_allclose(sm.receiver_depth, 4.0, rtol=1e-6)
    # The bunny spans heights 1..2: depths 2..3, back behind front.
    front, back = sm.occluder_depth, sm.occluder_depth_back
    hit = np.isfinite(front)
    assert np.array_equal(hit, np.isfinite(back))
    assert front[hit].min() >= 2.0 - 1e-5 and back[hit].max() <= 3.0 + 1e-5
    assert np.all(back[hit] >= front[hit])
    assert set(sm.timings) == {"transform", "extent", "raster_receivers", "raster_occluders", "shadow"}
    assert sm.method.name == "ssm" and sm.passes == 2 and sm.extent_fitted


def test_two_passes_never_lighter_than_one(bunny):
    scene, light = bunny
    one = ss.soft_shadow_map(scene, light, resolution=128, passes=1).visibility
    two = ss.soft_shadow_map(scene, light, resolution=128, passes=2).visibility
    assert np.all(two <= one + 1e-7)
    assert (one - two).max() > 0.1  # the back layer matters on the bunny
    one_only = ss.soft_shadow_map(scene, light, resolution=128, passes=1)
    assert one_only.occluder_depth_back is None


def test_map_orientation_follows_u_and_v():
    # A plate offset toward +u and +v (light frame: u = -x, v = +z) shadows the
    # top-right of the map: columns grow with u, row 0 is the +v edge.
    light = scenes.default_light()
    plate = scenes.quad((-0.6, 2.0, 0.6), 0.25)
    scene = ss.Scene(occluders=[plate], receivers=[scenes.floor()])
    sm = ss.soft_shadow_map(scene, light, resolution=64, passes=1, extent=0.5)
    dark = sm.visibility < 0.5
    rows, cols = np.nonzero(dark)
    assert rows.max() < 32 and cols.min() >= 32


def test_sample_at_receiver_points_reproduces_the_map(bunny):
    scene, light = bunny
    sm = ss.soft_shadow_map(scene, light, resolution=96)
    pts, idx = sm.receiver_points()
    assert pts.shape == (96 * 96, 3) and idx.shape == (96 * 96,)
    np.testing.assert_allclose(pts[:, 1], 0.0, atol=1e-5)  # on the floor
    v = sm.sample(pts)
    assert v.dtype == np.float32
    # Same sums, grouped differently: equal to float rounding.
    np.testing.assert_allclose(v, sm.visibility.ravel()[idx], atol=1e-5)


def test_sample_between_texels_and_outside(bunny):
    scene, light = bunny
    sm = ss.soft_shadow_map(scene, light, resolution=128)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-3, 3, 500), np.zeros(500), rng.uniform(-3, 3, 500)])
    v = sm.sample(pts)
    assert np.all((v >= 0) & (v <= 1))
    tx, ty = sm.extent
    q = pts - np.asarray(light.center)
    x, y = q @ light.u / (q @ light.n), q @ light.v / (q @ light.n)
    outside = (np.abs(x) > tx) | (np.abs(y) > ty)
    assert outside.any() and (~outside).any()
    assert np.all(v[outside] == 1.0)  # fitted extent: no shadow can fall there
    assert v[~outside].min() < 0.5
    # With an explicit extent, points outside it are an error unless given a value.
    sm2 = ss.soft_shadow_map(scene, light, resolution=64, extent=sm.extent)
    with pytest.raises(ValueError, match="points.*outside"):
        sm2.sample(pts)
    np.testing.assert_array_equal(sm2.sample(pts, outside=0.5)[outside], 0.5)
    with pytest.raises(ValueError, match="points"):
        sm.sample(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="points"):
        sm.sample([[0.0, np.nan, 0.0]])


def test_scene_accepts_trimesh_and_pairs():
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    box.apply_translation((0, 2, 0))
    light = scenes.default_light()
    a = ss.soft_shadow_map(ss.Scene(occluders=box, receivers=[scenes.floor()]), light, resolution=64)
    b = ss.soft_shadow_map(
        ss.Scene(occluders=[(box.vertices, box.faces)], receivers=scenes.floor()), light, resolution=64
    )
    np.testing.assert_array_equal(a.visibility, b.visibility)


def test_gil_is_released_during_the_work(bunny):
    # Two threads computing at once finish with the same answers (and the
    # calls do not serialize on the GIL: the work runs in py.detach).
    import threading

    scene, light = bunny
    ref = ss.soft_shadow_map(scene, light, resolution=64).visibility
    out = []
    threads = [
        threading.Thread(target=lambda: out.append(ss.soft_shadow_map(scene, light, resolution=64).visibility))
        for _ in range(4)
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(out) == 4 and all(np.array_equal(o, ref) for o in out)
