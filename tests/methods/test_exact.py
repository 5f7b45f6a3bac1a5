"""method="exact": ray casting against the occluder triangles."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import metrics, scenes


def test_plate_matches_the_closed_form():
    from .test_closed_form import exact_visibility

    scene, light = scenes.square_plate(side=1.0, height=2.0)
    sm = ss.soft_shadow_map(scene, light, resolution=48, method="exact", samples=1024)
    w, h = sm.resolution
    tx, ty = sm.extent
    x = (-1 + 2 * (np.arange(w) + 0.5) / w) * tx
    y = (1 - 2 * (np.arange(h) + 0.5) / h) * ty
    exact = exact_visibility(x[None, :], y[:, None], 0.25, 2.0, 4.0, 1.0, 1.0)
    # 32x32 strata: the shadow's two x-edges and two y-edges cross at most
    # 4 x 32 strata, each off by at most 1/1024.
    assert np.abs(sm.visibility - exact).max() <= 4 * 32 / 1024
    assert np.abs(sm.visibility - exact).mean() < 0.01
    assert sm.occluder_depth is None and sm.occluder_depth_back is None and sm.method.samples == 1024
    assert "raster_occluders" not in sm.timings  # no occluder map is made


def test_converges_to_the_mitsuba_reference(reference_for):
    scene, light = scenes.bunny_floating()
    errors = {}
    for k in (16, 64, 256):
        sm = ss.soft_shadow_map(scene, light, resolution=128, method="exact", samples=k)
        ref = reference_for("bunny_floating", sm, scene.occluders)
        errors[k] = metrics.shadow_error(sm.visibility, ref)
    # Error ~ 1/sqrt(samples) until it meets the reference's own noise
    # (1024 samples: about 0.003 of this metric). Measured: 0.036, 0.013, 0.005.
    assert errors[16] / errors[64] > 2.0, errors
    assert errors[64] / errors[256] > 1.6, errors
    assert errors[256] < 0.0065, errors


def test_deterministic_and_sampled_points_agree_with_the_map():
    scene, light = scenes.torus_floating()
    a = ss.soft_shadow_map(scene, light, resolution=40, method="exact", samples=64)
    b = ss.soft_shadow_map(scene, light, resolution=40, method="exact", samples=64)
    np.testing.assert_array_equal(a.visibility, b.visibility)
    pts, idx = a.receiver_points()
    v = a.sample(pts)
    # Same rays at the same points; the jitter differs (keyed by index), so
    # the two agree to the sampling noise of 64 samples.
    d = np.abs(v - a.visibility.ravel()[idx])
    assert d.mean() < 0.02 and d.max() <= 0.3


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(method="exact", samples=0), ValueError, "samples"),
        (dict(method="exact", samples=1 << 20), ValueError, "samples"),
        (dict(method="exact", samples=2.5), TypeError, "samples"),
        (dict(method="ssm", samples=16), ValueError, "samples"),
    ],
)
def test_bad_samples(kwargs, exc, words):
    scene, light = scenes.square_plate()
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map(scene, light, resolution=8, **kwargs)


def test_depth_maps_cannot_be_traced():
    occ = np.full((4, 4), 2.0, np.float32)
    rec = np.full((4, 4), 4.0, np.float32)
    with pytest.raises(ValueError, match="method.*triangles"):
        ss.soft_shadow_map_from_depth(occ, rec, light_size=1, extent=0.5, method="exact")


def test_a_probe_keeps_exacts_answer_where_it_is_unsure_and_costs_fewer_rays():
    # Light view: texels the 16-ray probe (and its 3x3 neighbours) saw
    # wholly lit or wholly blocked keep 1 or 0; the others are exact's bits.
    scene, light = scenes.bunny_floating()
    full = ss.soft_shadow_map(scene, light, resolution=96, method=ss.Exact())
    probed = ss.soft_shadow_map(scene, light, resolution=96, method=ss.Exact(probe=16))
    assert probed.method == ss.Exact(samples=256, probe=16, engine="rays")
    differ = probed.visibility != full.visibility
    assert np.isin(probed.visibility[differ], (0.0, 1.0)).all()
    shadowed = full.visibility < 1
    assert np.abs(probed.visibility - full.visibility)[shadowed].mean() < 1e-3
    # The umbra is kept from the probe: some texels are exactly 0 in both.
    assert ((probed.visibility == 0) & (full.visibility == 0)).any()


def test_a_probe_in_the_eye_view_matches_exact_on_a_closed_box_scene():
    from softshadow.scenes import as_built

    scene, light, cam = as_built.SCENES["blocks_on_table"]((96, 72))
    full = ss.render(scene, light, cam, method=ss.Exact())
    probed = ss.render(scene, light, cam, method=ss.Exact(probe=16))
    differ = probed.visibility != full.visibility
    assert np.isin(probed.visibility[differ], (0.0, 1.0)).all()
    shadowed = full.visibility < 1
    assert np.abs(probed.visibility - full.visibility)[shadowed].mean() < 2e-3
    # Deterministic.
    again = ss.render(scene, light, cam, method=ss.Exact(probe=16))
    np.testing.assert_array_equal(again.visibility, probed.visibility)


@pytest.mark.parametrize(
    "kwargs, words",
    [(dict(probe=0), "probe: must be in"), (dict(probe=1 << 20), "probe: must be in")],
)
def test_bad_probe(kwargs, words):
    with pytest.raises(ValueError, match=words):
        ss.Exact(**kwargs)


def test_the_gpu_refuses_a_probe():
    scene, light = scenes.square_plate(side=1.0, height=2.0)
    # Refused when the config resolves, before any adapter is asked for.
    with pytest.raises(ValueError, match="^probe: the GPU backend traces every sample"):
        ss.soft_shadow_map(scene, light, resolution=16, method=ss.Exact(probe=4), backend="gpu")
