"""Every image can say how right it is: ``estimate_error=True`` (always on
for ``Auto`` with a target) traces exact rays at a random subset of the pixels and reports
the mean |V - V_ref| over those in shadow, with a 95% interval
(src/eye/estimate.rs, src/error_estimate.rs; docs/accuracy.md).

The true error here is measured against ``exact`` with 1024 samples over
the whole image, so no Mitsuba is needed; the estimate's own rays have 256.
How many pixels it traces depends on the call's time (a tenth of it), so
the assertions hold for any draw size the CI machine gets.
"""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss
from softshadow.scenes import as_built

RES = (160, 120)


def _true_error(img, ref) -> float:
    """Mean |V - V_ref| over the pixels the reference shadows (same G-buffer)."""
    assert np.array_equal(img.mesh_id, ref.mesh_id)
    shadowed = img.mask & (1.0 - ref.visibility > 1e-3)
    return float(np.abs(img.visibility - ref.visibility)[shadowed].mean())


def test_off_by_default_on_when_asked_and_for_auto():
    scene, light, cam = as_built.torus_on_slab(RES)
    assert ss.render(scene, light, cam, method=ss.Ssm()).error_estimate is None
    img = ss.render(scene, light, cam, method=ss.Ssm(), estimate_error=True)
    e = img.error_estimate
    assert isinstance(e, ss.ErrorEstimate)
    low, high = e.interval
    assert 0.0 <= low <= e.error <= high <= 1.0
    assert e.traced >= 128 and 0 < e.shadowed <= e.traced and e.samples == 256
    assert e.seconds > 0 and "estimate" in img.timings
    assert repr(e).startswith("ErrorEstimate(error=")
    # The image itself does not change.
    np.testing.assert_array_equal(img.visibility, ss.render(scene, light, cam, method=ss.Ssm()).visibility)
    # The default call ("auto", no target) stays as fast as it was.
    assert ss.render(scene, light, cam).error_estimate is None
    planned = ss.render(scene, light, cam, method=ss.Auto(error=0.05))
    assert planned.error_estimate is not None
    assert any(d.name == "estimate" for d in planned.plan.decisions)


def test_exact_is_checked_against_four_times_its_samples():
    scene, light, cam = as_built.torus_on_slab(RES)
    e = ss.render(scene, light, cam, method=ss.Exact(samples=16), estimate_error=True).error_estimate
    assert e.samples == 64


# Scenes whose error is spread over their shadows. Where it sits in a few
# percent of the shadowed pixels (room_window at this size: ssm's error is
# the floor under the table, 5.7% of them), the 128 pixels a 50 ms call can
# afford miss it about half the time and the interval is too narrow: a
# measured limit (docs/accuracy.md), not asserted away here.
@pytest.mark.parametrize("name", ["torus_on_slab", "blocks_on_table", "bunny_on_slab"])
@pytest.mark.parametrize("method", [ss.Ssm(), ss.Bitmask(samples=64)], ids=lambda m: m.name)
def test_the_estimate_is_near_the_true_error(name, method):
    scene, light, cam = as_built.SCENES[name](RES)
    ref = ss.render(scene, light, cam, method=ss.Exact(samples=1024))
    img = ss.render(scene, light, cam, method=method, estimate_error=True)
    truth = _true_error(img, ref)
    e = img.error_estimate
    # Within a factor of two, or inside the interval widened by the
    # reference's own noise (1024 stratified samples: a few 1e-3).
    low, high = e.interval
    assert truth / 2 <= e.error <= 2 * truth or low - 0.005 <= truth <= high + 0.005, (truth, e)


def test_a_fixed_draw_gives_the_same_estimate_every_time():
    scene, light, cam = as_built.torus_on_slab(RES)
    a = ss.render(scene, light, cam, method=ss.Ssm(), estimate_error="fixed").error_estimate
    b = ss.render(scene, light, cam, method=ss.Ssm(), estimate_error="fixed").error_estimate
    assert a.traced == 1024 and (a.error, a.interval, a.shadowed) == (b.error, b.interval, b.shadowed)
    timed = ss.render(scene, light, cam, method=ss.Ssm(), estimate_error="timed").error_estimate
    assert timed.samples == a.samples and timed.traced >= 128


def test_bad_estimate_error_is_refused():
    scene, light, cam = as_built.torus_on_slab(RES)
    with pytest.raises(ValueError, match="estimate_error"):
        ss.render(scene, light, cam, estimate_error="yes")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="estimate_error"):
        ss.render(scene, light, cam, estimate_error=1)  # type: ignore[arg-type]
