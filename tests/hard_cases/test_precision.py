"""precision=: the paper's FP16 study (Figure 14, Appendix A) and the f32 default."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes
from softshadow.experiments.fp16 import condition_4

# A square plate at depth 2 over a parallel floor at depth 4, light 1x1,
# tangent extent 0.5: at N² each micro-patch hides (4 / N)² = (128 / N)² 2^-10 of the
# light, so N = 128 sits exactly on condition (4).
ZO, ZR, HALF, EXTENT, RECEIVERS = 2.0, 4.0, 0.25, 0.5, 64


def plate(n):
    c = (np.arange(n) + 0.5) / n * 2 * EXTENT - EXTENT
    x, y = np.meshgrid(c, -c)
    return np.where((abs(x) < HALF) & (abs(y) < HALF), ZO, np.inf).astype(np.float32)


def plate_closed_form(n):
    c = (np.arange(n) + 0.5) / n * 2 * EXTENT - EXTENT
    k = ZR * ZO / (ZR - ZO)

    def overlap(t):
        return np.clip(k * (HALF - t) + 0.5, 0, 1) - np.clip(k * (-HALF - t) + 0.5, 0, 1)

    return 1 - np.outer(overlap(-c), overlap(c))


def plate_error(n, precision):
    rec = np.full((RECEIVERS, RECEIVERS), ZR, np.float32)
    sm = ss.soft_shadow_map_from_depth(plate(n), rec, light_size=1.0, extent=EXTENT, precision=precision)
    return float(np.abs(sm.visibility - plate_closed_form(RECEIVERS)).max())


@pytest.mark.parametrize("n", [64, 128, 256, 512])
def test_condition_4_predicts_where_fp16_breaks_on_the_plate(n):
    holds = condition_4(n, 1.0, EXTENT, ZO, ZR)
    err = plate_error(n, "f16")
    assert bool(holds) == (n <= 128)
    if holds:
        assert err < 1e-3, err
    else:
        # The umbra's FP16 sum stops growing where one share is half an ulp,
        # at 2^11 shares: 0.5 at 256², 0.125 at 512².
        assert err == pytest.approx(1 - 2.0**11 * (4 / n) ** 2, abs=1e-3)
    # Batching repairs it; f32 and f64 hold everywhere.
    assert plate_error(n, "f16-batched") < 1e-3
    assert plate_error(n, "f32") < 1e-5
    assert plate_error(n, "f64") < 1e-5


def test_figure_14_on_the_bunny():
    # 128² holds, 512² breaks, batching repairs it (docs/precision/fp16.md).
    scene, light = scenes.bunny_floating(light_size=0.5)
    diff = {}
    for n in (128, 512):
        sm = ss.soft_shadow_map(scene, light, resolution=n, passes=1, precision="f64")
        for p in ("f32", "f16", "f16-batched"):
            v = ss.soft_shadow_map_from_depth(
                sm.occluder_depth, sm.receiver_depth, light_size=light.size, extent=sm.extent, precision=p
            ).visibility
            d = np.abs(v - sm.visibility)
            diff[n, p] = (float(d.mean()), float(d.max()))
    assert diff[128, "f16"][0] < 0.005, diff  # measured 0.0021
    assert diff[512, "f16"][0] > 0.05 and diff[512, "f16"][1] > 0.5, diff  # 0.11, 0.70
    assert diff[512, "f16-batched"][0] < 0.001 and diff[512, "f16-batched"][1] < 0.01, diff  # 0.0002, 0.004
    for n in (128, 512):
        assert diff[n, "f32"][1] < 1e-5, diff


@pytest.mark.slow
def test_f32_holds_to_1e_4_of_f64_at_4096():
    # Occluder maps at 4096², shaded at 64x64 of the 4096² output's texel
    # centers (every 64th: the whole map would take minutes): each sum has up
    # to ~6e5 micro-patches. Plain f32 sums were measured 3e-3 off here; the
    # row-by-row two-level sum keeps the difference near 1e-6.
    scene, light = scenes.bunny_floating()
    n = 4096
    maps = {
        p: ss.soft_shadow_map(scene, light, resolution=64, occluder_resolution=n, precision=p) for p in ("f32", "f64")
    }
    sm = maps["f64"]
    tx, ty = sm.extent
    k = np.arange(32, n, 64)
    x = (-1 + 2 * (k + 0.5) / n) * tx
    y = (1 - 2 * (k + 0.5) / n) * ty
    xx, yy = np.meshgrid(x, y)
    # The floor's top is a plane parallel to the light: one planar depth.
    z = float(np.nanmedian(np.where(np.isfinite(sm.receiver_depth), sm.receiver_depth, np.nan)))
    u, v, nrm, c = (np.asarray(a) for a in (light.u, light.v, light.n, light.center))
    pts = c + z * (nrm + xx.reshape(-1, 1) * u + yy.reshape(-1, 1) * v)
    v32, v64 = maps["f32"].sample(pts), maps["f64"].sample(pts)
    assert (v64 < 0.99).mean() > 0.1  # the points cover the shadow
    assert np.abs(v32 - v64).max() < 1e-4
