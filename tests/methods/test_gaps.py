"""bitmask's gaps: connected micro-quads (gaps="closed", the default) against
the flat micro-patches (gaps="open"), against ray-cast ``exact``.

Measured at 128², 256 samples, against 1024-sample ``exact`` (itself within
0.0012-0.0019 of 4096-sample ``exact`` on these scenes):

* the plate tilted 30°: open 0.0156 (mean signed +0.0105: light through the
  gaps), closed 0.0064 (-0.0004);
* two flat plates at different depths meeting in the light's view: 0.0046,
  the same bits open and closed (the step between them is no surface);
* the plate parallel to the light: the same bits open and closed.
"""

import numpy as np
import pytest

import softshadow as ss
from softshadow import metrics, scenes

RES = 128


def two_plates_at_different_depths() -> tuple[ss.Scene, ss.RectLight]:
    """Plate A at height 2 over x < 0 and B at 2.6 over x > 0: their edges meet
    at the light's centre line, so in the occluder map they are neighbours
    with a depth step; seen from a receiver off the centre line light passes
    between them."""
    f = np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32)
    a = np.array([[-0.5, 2.0, -0.4], [0.0, 2.0, -0.4], [0.0, 2.0, 0.4], [-0.5, 2.0, 0.4]])
    b = np.array([[0.0, 2.6, -0.4], [0.35, 2.6, -0.4], [0.35, 2.6, 0.4], [0.0, 2.6, 0.4]])
    return ss.Scene(occluders=[(a, f), (b, f)], receivers=[scenes.floor()]), scenes.default_light(1.0)


def maps(scene: ss.Scene, light: ss.RectLight) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(exact with 1024 samples, bitmask open, bitmask closed) at RES²."""
    ref = ss.soft_shadow_map(scene, light, resolution=RES, method=ss.Exact(samples=1024)).visibility
    open_, closed = (
        ss.soft_shadow_map(scene, light, resolution=RES, method=ss.Bitmask(gaps=g)).visibility
        for g in ("open", "closed")
    )
    return ref, open_, closed


def signed(v: np.ndarray, ref: np.ndarray) -> float:
    """Mean V - V_ref over the reference's shadow (> 0: too light)."""
    return float(np.mean((v - ref)[metrics.shadow_mask(ref)]))


def test_a_tilted_plate_lets_no_light_through_its_gaps():
    ref, open_, closed = maps(*scenes.tilted_plate())
    # The flat patches leak: too light on average, by far more than the noise.
    assert signed(open_, ref) > 0.008
    # Connected quads: no bias toward the light, and the error less than half.
    assert abs(signed(closed, ref)) < 0.002
    err = metrics.shadow_error(closed, ref)
    assert err <= 0.0064 * 1.15, err
    assert err < 0.5 * metrics.shadow_error(open_, ref)


@pytest.mark.parametrize("make", [scenes.square_plate, two_plates_at_different_depths])
def test_flat_plates_and_the_step_between_two_give_the_bits_of_open_gaps(make):
    # A plate parallel to the light has one depth: its quads are its patches.
    # Two plates at different depths are a step far steeper than any surface
    # the rule connects: no bridge between them, so the light between them
    # stays (the same bits as the flat patches), and the result is close to
    # the ray-cast one.
    ref, open_, closed = maps(*make())
    assert np.array_equal(open_, closed)
    assert metrics.shadow_error(closed, ref) <= 0.0071 * 1.15


def test_gaps_is_checked_and_reported():
    assert ss.Bitmask().gaps == "closed"
    assert ss.Bitmask(gaps="open").to_dict()["gaps"] == "open"
    assert ss.Bitmask(**ss.Bitmask(gaps="open").to_dict()) == ss.Bitmask(gaps="open")
    with pytest.raises(ValueError, match="gaps.*closed.*open"):
        ss.Bitmask(gaps="shut")
    with pytest.raises(TypeError, match="gaps"):
        ss.Bitmask(gaps=1)  # type: ignore[arg-type]
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=16, method=ss.Bitmask(gaps="open"))
    assert sm.method.gaps == "open"


def test_1024_samples_are_closer_to_the_ray_cast_reference():
    scene, light = scenes.tilted_plate()
    ref = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Exact(samples=4096)).visibility
    err = {
        k: metrics.shadow_error(
            ss.soft_shadow_map(scene, light, resolution=64, method=ss.Bitmask(samples=k)).visibility, ref
        )
        for k in (256, 1024)
    }
    assert err[1024] < err[256], err
