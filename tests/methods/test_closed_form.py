"""A square plate parallel to the light over a parallel floor: closed form.

Seen from a floor point at tangent (xr, yr) and depth zR, the plate (tangent
square [-a, a]^2 at depth zO) back-projects onto the light's plane as the
square k [-a - xr, a - xr] x k [-a - yr, a - yr], k = zR zO / (zR - zO)
(a homothety of center the floor point), and the occluded fraction is its
overlap with the light [-Lx/2, Lx/2] x [-Ly/2, Ly/2] divided by Lx Ly.

Discretization bound. The occluder map keeps the texels whose centers fall in
the plate, so each of the plate's four edges moves by at most half a texel (hw
along x, hh along y, in tangent units). The micro-patches of a flat plate tile
its back-projection exactly (no overlap, no gap), so the SSM is exact for the
discretized plate. Moving one x-edge by delta changes the back-projected
interval by k delta, its overlap with the light by at most k delta, and the
fraction (a product of two factors <= 1) by at most k delta / Lx. Summing over
the four edges: |V_ssm - V_exact| <= 2 k (hw / Lx + hh / Ly).
"""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes


def exact_visibility(x, y, a, zo, zr, lx, ly):
    k = zr * zo / (zr - zo)

    def overlap(c, half_l):
        lo = np.clip(k * (-a - c), -half_l, half_l)
        hi = np.clip(k * (a - c), -half_l, half_l)
        return (hi - lo) / (2 * half_l)

    return 1.0 - overlap(x, lx / 2) * overlap(y, ly / 2)


@pytest.mark.parametrize("resolution", [64, 128, 257])
@pytest.mark.parametrize("passes", [1, 2])
@pytest.mark.parametrize("light_size", [(1.0, 1.0), (2.0, 0.5)])
def test_plate_stays_within_the_half_texel_bound(resolution, passes, light_size):
    side, height = 1.0, 2.0
    scene, _ = scenes.square_plate(side=side, height=height)
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=light_size)
    sm = ss.soft_shadow_map(scene, light, resolution=resolution, passes=passes)
    zo, zr = 4.0 - height, 4.0
    a = (side / 2) / zo
    w, h = sm.resolution
    tx, ty = sm.extent
    x = (-1 + 2 * (np.arange(w) + 0.5) / w) * tx
    y = (1 - 2 * (np.arange(h) + 0.5) / h) * ty
    exact = exact_visibility(x[None, :], y[:, None], a, zo, zr, *light_size)
    k = zr * zo / (zr - zo)
    bound = 2 * k * (tx / w / light_size[0] + ty / h / light_size[1])
    err = np.abs(sm.visibility - exact)
    assert err.max() <= bound + 1e-5, (err.max(), bound)
    # The fitted extent is the hand-computed one: |x| + Lx/2 (1/zO - 1/zR),
    # where the exact penumbra ends.
    np.testing.assert_allclose(
        sm.extent, [a + light_size[0] / 2 * (1 / zo - 1 / zr), a + light_size[1] / 2 * (1 / zo - 1 / zr)], rtol=1e-12
    )


def test_plate_aligned_with_texels_is_exact():
    # Extent chosen so the plate's edges fall on texel edges: no discretization.
    zo, zr, a = 2.0, 4.0, 0.25
    n = 64
    tx = a * 2  # plate covers the middle half of the map: 16 texels each side
    x = (-1 + 2 * (np.arange(n) + 0.5) / n) * tx
    occ = np.where((np.abs(x)[None, :] < a) & (np.abs(x)[:, None] < a), zo, np.inf).astype(np.float32)
    rec = np.full((n, n), zr, np.float32)
    sm = ss.soft_shadow_map_from_depth(occ, rec, light_size=(1.0, 1.0), extent=(tx, tx))
    exact = exact_visibility(x[None, :], x[::-1][:, None], a, zo, zr, 1.0, 1.0)
    np.testing.assert_allclose(sm.visibility, exact, atol=2e-6)
