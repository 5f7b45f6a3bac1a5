"""The light view's error estimate (``soft_shadow_map(...,
estimate_error=...)``, ``sm.error_estimate``) and ``Auto(error=e)`` checked
against it: exact rays from a drawn subset of the receiver texels, keyed as
``exact`` keys them (the Rust test in src/light_view/estimate.rs checks
that ``exact`` against its own samples gives exactly 0)."""

from __future__ import annotations

import pytest

import softshadow as ss
from softshadow import scenes
from softshadow.metrics import shadow_error


def _plate(**kw: object) -> ss.ShadowMap:
    scene, light = scenes.square_plate()
    return ss.soft_shadow_map(scene, light, resolution=64, **kw)  # type: ignore[arg-type]


def test_off_by_default() -> None:
    assert _plate().error_estimate is None
    assert _plate(estimate_error=False).error_estimate is None


def test_on_when_asked() -> None:
    e = _plate(estimate_error=True).error_estimate
    assert isinstance(e, ss.ErrorEstimate)
    lo, hi = e.interval
    # Maps are checked against 1024 light samples (256 erred 0.008 alone
    # on the fence).
    assert e.traced > 0 and e.shadowed > 0 and e.samples == 1024
    assert 0.0 <= lo <= e.error <= hi <= 1.0
    assert e.seconds >= 0.0


def test_a_fixed_draw_is_deterministic() -> None:
    scene, light = scenes.bunny_floating()
    runs = [ss.soft_shadow_map(scene, light, resolution=128, estimate_error="fixed") for _ in range(2)]
    a, b = (r.error_estimate for r in runs)
    assert a is not None and b is not None
    assert a.traced == 1024
    assert (a.error, a.interval, a.traced, a.shadowed) == (b.error, b.interval, b.traced, b.shadowed)


def test_exact_is_checked_against_four_times_its_samples() -> None:
    sm = _plate(method=ss.Exact(samples=64), estimate_error="fixed")
    e = sm.error_estimate
    assert e is not None and e.samples == 256  # four times exact's
    # exact's own sampling error: the estimate from 1024 texels is the
    # error over the whole map against the same 256-sample rays (measured
    # 0.0139 and 0.0131).
    scene, light = scenes.square_plate()
    ref = ss.soft_shadow_map(scene, light, resolution=64, extent=sm.extent, method=ss.Exact(samples=256))
    truth = shadow_error(sm.visibility, ref.visibility)
    assert abs(e.error - truth) < 0.002, (e, truth)


def test_a_scene_shadowing_itself_estimates_too() -> None:
    scene, light = scenes.bunny_on_floor()
    whole = ss.Scene(meshes=[*scene.occluders, *scene.receivers])
    sm = ss.soft_shadow_map(whole, light, resolution=64, estimate_error="fixed")
    assert sm.error_estimate is not None and sm.error_estimate.traced > 0


def test_bad_input_names_the_argument() -> None:
    with pytest.raises(ValueError, match="estimate_error"):
        _plate(estimate_error="sometimes")
    with pytest.raises(TypeError, match="estimate_error"):
        _plate(estimate_error=1)
    # Depth maps have no triangles to trace: the argument does not exist.
    base = _plate()
    assert base.occluder_depth is not None
    with pytest.raises(TypeError, match="estimate_error"):
        ss.soft_shadow_map_from_depth(  # type: ignore[call-arg]
            base.occluder_depth,
            base.receiver_depth,
            light_size=(1.0, 1.0),
            extent=base.extent,
            estimate_error=True,
        )


@pytest.mark.slow
def test_auto_on_the_fence_meets_its_target() -> None:
    # Issue 28: the plan claimed 0.005 on the fence. Its bitmask setting
    # measured 0.0039 against exact at 1024 samples (0.0029 against 4096)
    # and its estimate's upper end 0.0044: kept; had it missed, exact would
    # have run.
    scene, light = scenes.fence()
    sm = ss.soft_shadow_map(scene, light, resolution=256, method=ss.Auto(error=0.005))
    assert sm.plan is not None and sm.error_estimate is not None
    names = [d.name for d in sm.plan.decisions]
    assert "estimate" in names and names[-1] == "target" and sm.plan.decisions[-1].taken, sm.plan
    assert sm.plan.method == sm.method
    assert sm.error_estimate.interval[1] <= 0.005
    ref = ss.soft_shadow_map(scene, light, resolution=256, extent=sm.extent, method=ss.Exact(samples=1024))
    assert shadow_error(sm.visibility, ref.visibility) <= 0.005


def test_auto_refines_until_its_target_is_met() -> None:
    # The square plate at 64x64: the planned ssm's estimate misses 0.005,
    # exact runs instead (the plan keeps the planned setting aside).
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Auto(error=0.005))
    assert sm.plan is not None and sm.error_estimate is not None
    names = [d.name for d in sm.plan.decisions]
    assert "refine" in names and "estimate" in names, sm.plan
    assert names[-1] == "target" and sm.plan.decisions[-1].taken, sm.plan
    assert sm.plan.method == sm.method and isinstance(sm.method, ss.Exact)
    assert isinstance(sm.plan.planned, ss.Ssm)
    assert list(sm.timings)[:2] == ["plan", "replaced"]
    ref = ss.soft_shadow_map(scene, light, resolution=64, extent=sm.extent, method=ss.Exact(samples=4096))
    assert shadow_error(sm.visibility, ref.visibility) <= 0.005
    planned = ss.soft_shadow_map(scene, light, resolution=64, extent=sm.extent, method=sm.plan.planned)
    assert shadow_error(planned.visibility, ref.visibility) > shadow_error(sm.visibility, ref.visibility)
