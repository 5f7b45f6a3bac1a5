"""Soft shadow maps against Mitsuba 3 references (1024 stratified samples).

Thresholds are the errors measured with this implementation plus about 12%
(the reference's own noise at 1024 samples is about 0.003 of the metric); the
paper's method leaves 0.03-0.05 on curved occluders (overlapping and gapping
micro-patch back-projections, §4.1.2, and parts hidden from the light's
center, §4.1.1). A flipped axis, a wrong extent or a lost pass raises the
error far past them (see test_mutations_are_caught).
"""

import numpy as np
import pytest

import softshadow as ss
from softshadow import metrics, scenes

pytest.importorskip("mitsuba")

# (scene, resolution, passes) -> largest accepted error (the paper's metric).
# Measured: plate 0.0070/0.0036 (128/256, both passes); bunny floating
# 0.0394/0.0311 at 128 and 0.0396/0.0317 at 256 (1/2 passes); bunny on floor
# 0.0546/0.0286 and 0.0543/0.0280; torus 0.0387/0.0330 and 0.0386/0.0319.
THRESHOLDS = {
    ("square_plate", 128, 1): 0.008,
    ("square_plate", 128, 2): 0.008,
    ("square_plate", 256, 1): 0.0042,
    ("square_plate", 256, 2): 0.0042,
    ("bunny_floating", 128, 1): 0.044,
    ("bunny_floating", 128, 2): 0.035,
    ("bunny_floating", 256, 1): 0.044,
    ("bunny_floating", 256, 2): 0.0355,
    ("bunny_on_floor", 128, 1): 0.061,
    ("bunny_on_floor", 128, 2): 0.032,
    ("bunny_on_floor", 256, 1): 0.061,
    ("bunny_on_floor", 256, 2): 0.0315,
    ("torus", 128, 1): 0.043,
    ("torus", 128, 2): 0.037,
    ("torus", 256, 1): 0.043,
    ("torus", 256, 2): 0.036,
}


@pytest.fixture(scope="module")
def built():
    return {name: scenes.SCENES[name]() for name in ("square_plate", "bunny_floating", "bunny_on_floor", "torus")}


def errors(built, reference_for, name, res):
    scene, light = built[name]
    out = {}
    ref = None
    for passes in (1, 2):
        sm = ss.soft_shadow_map(scene, light, resolution=res, passes=passes)
        if ref is None:
            ref = reference_for(name, sm, scene.occluders)
        out[passes] = metrics.shadow_error(sm.visibility, ref)
    return out, ref


@pytest.mark.parametrize("res", [128, 256])
@pytest.mark.parametrize("name", ["square_plate", "bunny_floating", "bunny_on_floor", "torus"])
def test_error_against_mitsuba(built, reference_for, name, res):
    err, ref = errors(built, reference_for, name, res)
    assert (1.0 - ref > 1e-3).mean() > 0.2  # the map is mostly shadow: extent fits it
    for passes in (1, 2):
        assert err[passes] <= THRESHOLDS[(name, res, passes)], (name, res, passes, err)
    if name != "square_plate":
        # The back layer recovers occluder parts hidden from the light's center.
        assert err[2] < err[1] - 0.005, err


def test_mutations_are_caught(built, reference_for):
    """What the thresholds exist for: each deliberate mistake fails them."""
    name, res = "bunny_floating", 128
    scene, light = built[name]
    sm = ss.soft_shadow_map(scene, light, resolution=res, passes=2)
    ref = reference_for(name, sm, scene.occluders)
    limit = THRESHOLDS[(name, res, 2)]
    assert metrics.shadow_error(sm.visibility, ref) <= limit
    # Flipped axes.
    assert metrics.shadow_error(sm.visibility[::-1], ref) > 2 * limit
    assert metrics.shadow_error(sm.visibility[:, ::-1], ref) > 2 * limit
    # A 10% wrong extent, either way. (5% too wide goes unseen: measured 0.027,
    # since the published method's shadows are slightly too wide, §4.1.2.)
    for scale in (0.9, 1.1):
        ext = (sm.extent[0] * scale, sm.extent[1] * scale)
        wrong = ss.soft_shadow_map(scene, light, resolution=res, passes=2, extent=ext)
        assert metrics.shadow_error(wrong.visibility, ref) > limit, scale
    # A light of the wrong size.
    big = ss.RectLight(light.center, light.normal, light.up, size=(1.2, 1.2))
    wrong = ss.soft_shadow_map(scene, big, resolution=res, passes=2, extent=sm.extent)
    assert metrics.shadow_error(wrong.visibility, ref) > limit
    # A lost pass.
    one = ss.soft_shadow_map(scene, light, resolution=res, passes=1)
    assert metrics.shadow_error(one.visibility, ref) > limit


def test_sample_matches_the_reference_at_points(built):
    reference = pytest.importorskip("softshadow.reference")
    scene, light = built["bunny_floating"]
    sm = ss.soft_shadow_map(scene, light, resolution=256, passes=2)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-0.8, 0.8, 3000), np.zeros(3000), rng.uniform(-0.8, 0.8, 3000)])
    v = sm.sample(pts)
    ref = reference.visibility_at_points(scene.occluders, light, pts, samples=1024)
    shadow = 1 - ref > 1e-3
    assert shadow.sum() > 1000
    # Measured 0.042: these points weigh the outer penumbra more than the
    # map's texels do (where the published method is least accurate).
    assert np.abs(v - ref)[shadow].mean() < 0.047
