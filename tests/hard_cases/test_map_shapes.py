"""Degenerate occluder maps and map shapes: empty, full, one texel, 1x1, 1xN."""

import numpy as np
import pytest

import softshadow as ss
from hard_cases import plate
from hard_cases.common import assert_visibility, options
from softshadow import scenes


def _from_depth(occ, rec, ext, method, backend, size=1.0):
    return ss.soft_shadow_map_from_depth(occ, rec, light_size=size, extent=ext, **options(method, backend)).visibility


def test_empty_occluder_map_casts_no_shadow(map_method, backend):
    occ = np.full((16, 24), np.inf, np.float32)
    rec = np.full((16, 24), 4.0, np.float32)
    np.testing.assert_array_equal(_from_depth(occ, rec, (0.5, 0.5), map_method, backend), 1.0)


def test_occluders_covering_every_texel(map_method, backend):
    # The whole map is one plate: the closed form of a plate as wide as the
    # map. Where the penumbra reach, 0.5 (1/2 - 1/4) = 0.125, stays inside the
    # map the receivers are in umbra.
    ext = (0.5, 0.5)
    occ = np.full((32, 32), 2.0, np.float32)
    rec = np.full((32, 32), 4.0, np.float32)
    v = _from_depth(occ, rec, ext, map_method, backend)
    assert_visibility(v)
    x = plate.centers(32, 0.5)
    want = plate.visibility(x[None, :], x[::-1][:, None], (-0.5, 0.5, -0.5, 0.5), 2.0, 4.0, 1.0, 1.0)
    assert np.abs(v - want).max() <= plate.bound(map_method)
    inner = (np.abs(x) < 0.5 - 0.125)[None, :] & (np.abs(x) < 0.5 - 0.125)[:, None]
    assert v[inner].max() <= 1e-6 and v.max() > 0.5  # corners see past the map


@pytest.mark.parametrize("where", [(0, 0), (7, 11), (15, 23)])
def test_single_occluder_texel(map_method, backend, where):
    ext = (0.6, 0.4)
    h, w = 16, 24
    j, i = where
    x = plate.centers(w, ext[0])
    y = plate.centers(h, ext[1])[::-1]
    hw, hh = ext[0] / w, ext[1] / h
    occ = np.full((h, w), np.inf, np.float32)
    occ[j, i] = 3.0
    rec = np.full((h, w), 4.0, np.float32)
    v = _from_depth(occ, rec, ext, map_method, backend, size=0.3)
    assert_visibility(v)
    rect = (x[i] - hw, x[i] + hw, y[j] - hh, y[j] + hh)
    want = plate.visibility(x[None, :], y[:, None], rect, 3.0, 4.0, 0.3, 0.3)
    assert np.abs(v - want).max() <= plate.bound(map_method)
    assert v.min() < 0.9  # it does cast a shadow


@pytest.mark.parametrize("shape", [(1, 1), (1, 37), (29, 1), (3, 200)])
def test_thin_maps_from_depth(map_method, backend, shape):
    # A plate over the middle third of the columns, all rows: closed form.
    h, w = shape
    ext = (0.45, 0.05)
    x = plate.centers(w, ext[0])
    y = plate.centers(h, ext[1])[::-1]
    cols = np.abs(x) < 0.15
    occ = np.where(cols[None, :], np.float32(2.5), np.float32(np.inf)).repeat(h, axis=0).astype(np.float32)
    rec = np.full(shape, 4.0, np.float32)
    v = _from_depth(occ, rec, ext, map_method, backend, size=0.5)
    assert_visibility(v)
    # The occluder map holds columns whose centers are inside: its edges.
    x0 = x[cols].min() - ext[0] / w if cols.any() else 0.0
    x1 = x[cols].max() + ext[0] / w if cols.any() else 0.0
    want = plate.visibility(x[None, :], y[:, None], (x0, x1, -ext[1], ext[1]), 2.5, 4.0, 0.5, 0.5)
    box = plate.box_texels(0.5, 2.5, 4.0, 2 * min(ext[0] / w, ext[1] / h))
    assert np.abs(v - want).max() <= plate.bound(map_method, box)


@pytest.mark.parametrize("resolution", [1, (1, 40), (40, 1), (2000, 1)])
def test_thin_maps_from_meshes(method, backend, resolution):
    # Square plate (tangent half-size 0.25) over extent 0.5. A map method sees
    # the plate as the texels whose centers it covers -- on a 1-row map one
    # row as tall as the map -- and is exact for that rectangle; the ray
    # caster sees the plate itself.
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=resolution, extent=0.5, **options(method, backend))
    assert_visibility(sm.visibility)
    w, h = (resolution, resolution) if isinstance(resolution, int) else resolution
    assert sm.visibility.shape == (h, w)
    x = plate.centers(w, 0.5)
    y = plate.centers(h, 0.5)[::-1]
    if method == "exact":
        rect, bound = (-0.25, 0.25, -0.25, 0.25), 4 * 16 / 256  # 4 edges x 16 strata
    elif method == "smoothies":
        # Fake soft shadows: the umbra is the hard shadow's and the penumbra
        # lies outside it, so across the true penumbra's inner half they read
        # 0 where the truth rises to 1/2 (measured max 0.45-0.499).
        rect, bound = (-0.25, 0.25, -0.25, 0.25), 0.5
    else:
        hw, hh = 0.5 / w, 0.5 / h
        xs, ys = x[np.abs(x) < 0.25], y[np.abs(y) < 0.25]
        rect = (xs.min() - hw, xs.max() + hw, ys.min() - hh, ys.max() + hh)
        bound = plate.bound(method, plate.box_texels(1.0, 2.0, 4.0, 1.0 / max(w, h)))
    want = plate.visibility(x[None, :], y[:, None], rect, 2.0, 4.0, 1.0, 1.0)
    assert np.abs(sm.visibility - want).max() <= bound
    if resolution == 1:  # its one texel looks at the plate's center: umbra
        assert sm.visibility[0, 0] <= 1e-6


def test_occluder_just_outside_the_receivers_still_shadows_them(method, backend):
    # Floor of tangent half-width 0.5; a plate at tangent 0.5-0.6 (depth 2)
    # casts a penumbra 0.125 wide back onto the floor's edge. The fitted
    # extent covers the occluder (extent.rs); cut at the receivers' own
    # extent, the map methods saw no occluder (V = 1 where exact gives 0.82).
    light = scenes.default_light()
    scene = ss.Scene(occluders=[scenes.quad((-1.1, 2.0, 0.0), 0.1)], receivers=[scenes.quad((0.0, 0.0, 0.0), 2.0)])
    sm = ss.soft_shadow_map(scene, light, resolution=64, **options(method, backend))
    assert sm.extent[0] == pytest.approx(0.6)
    ref = ss.soft_shadow_map(scene, light, resolution=64, method="exact", samples=4096).visibility
    assert_visibility(sm.visibility)
    assert ref.min() < 0.85 and sm.visibility.min() < 0.86
    shadow = ref < 1 - 1e-3
    # Smoothies put the hard shadow's umbra where the truth has none
    # (measured mean 0.128).
    assert np.abs(sm.visibility - ref)[shadow].mean() <= (0.15 if method == "smoothies" else 0.03)
