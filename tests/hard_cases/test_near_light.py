"""Occluder touching the light (z_O -> 0) and behind the light's plane (z_O <= 0).

A micro-patch at depth z_O back-projects onto the light with the factor
k = z_R z_O / (z_R - z_O) -> 0: a fixed tangent footprint near the light hides
a vanishing part of it, down to depths whose 1/z overflows f32 (1e-45),
where it hides nothing. Geometry at or behind the light's plane cannot block
a segment from the light to a receiver in front of it, so it casts no shadow:
the rasterizer clips it (at 1e-9 of the scene's depth) and the ray caster's
segments never reach it. Fitting the extent needs every occluder vertex in
front of the light (tests/api/test_bad_input.py); with an explicit extent such scenes work.
"""

import numpy as np
import pytest

import softshadow as ss
from hard_cases import plate
from hard_cases.common import assert_visibility, options
from softshadow import scenes

EXT = (0.5, 0.5)
RECT = (-0.25, 0.25, -0.25, 0.25)


@pytest.mark.parametrize("zo", [0.5, 1e-3, 1e-6, 1e-12, 1e-30, 1e-45])
def test_plate_approaching_the_light_follows_the_closed_form(map_method, backend, zo):
    occ, rec, x, y = plate.maps(64, 64, EXT, RECT, zo, 4.0)
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=1.0, extent=EXT, **options(map_method, backend)).visibility
    assert_visibility(v)
    want = plate.visibility(x[None, :], y[:, None], RECT, float(np.float32(zo)), 4.0, 1.0, 1.0)
    wide = plate.box_texels(1.0, float(np.float32(zo)), 4.0, 2 * EXT[0] / 64)
    assert np.abs(v - want).max() <= plate.bound(map_method, wide)
    if zo <= 1e-6:  # hides at most (2 k a)^2 < 1e-12 of the light
        np.testing.assert_allclose(v, 1.0, atol=1e-6)


def _crossing_quad(behind: float):
    # A quad sloping from depth -behind (behind the light) to depth 2.
    # Light at height 4 looking down: depth = 4 - y.
    y0, y1 = 4.0 + behind, 2.0
    v = np.array([[-0.5, y0, -0.5], [0.5, y1, -0.5], [0.5, y1, 0.5], [-0.5, y0, 0.5]])
    return v, np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32)


def _cut_quad():
    # The same quad's part in front of the light's plane (from depth 0 to 2).
    behind = 1.0
    t = behind / (behind + 2.0)  # where the slope crosses depth 0
    xc = -0.5 + t
    v = np.array([[xc, 4.0, -0.5], [0.5, 2.0, -0.5], [0.5, 2.0, 0.5], [xc, 4.0, 0.5]])
    return v, np.array([[0, 2, 1], [0, 3, 2]], dtype=np.uint32)


def test_geometry_behind_the_light_casts_no_shadow(method, backend):
    light = scenes.default_light()
    floor = scenes.floor()
    kw = dict(resolution=64, extent=1.0, **options(method, backend))
    crossing = ss.soft_shadow_map(ss.Scene(occluders=[_crossing_quad(1.0)], receivers=[floor]), light, **kw)
    cut = ss.soft_shadow_map(ss.Scene(occluders=[_cut_quad()], receivers=[floor]), light, **kw)
    assert_visibility(crossing.visibility)
    # The same shadow from the quad and from its part in front of the light
    # (clipping at 1e-9 of the depth instead of 0 moves nothing visible; the
    # ray caster's triangles differ in rounding: one sample of 256 at most).
    d = np.abs(crossing.visibility - cut.visibility)
    assert d.max() <= (1 / 256 if method == "exact" else 1e-5) and d.mean() <= 1e-5
    # The part in front still shadows (pcss: one mean blocker depth for a
    # quad spanning depths 0 to 2 widens its filter; measured min 0.737).
    assert crossing.visibility.min() < (0.8 if method == "pcss" else 0.65)


def test_occluder_wholly_behind_or_on_the_light_plane(method, backend):
    light = scenes.default_light()
    kw = dict(resolution=32, extent=0.5, **options(method, backend))
    for y in (4.0, 4.5):  # on the light's plane, then behind it
        scene = ss.Scene(occluders=[scenes.quad((0.0, y, 0.0), 0.5)], receivers=[scenes.floor()])
        v = ss.soft_shadow_map(scene, light, **kw).visibility
        np.testing.assert_array_equal(v, 1.0)


def test_vertex_touching_the_light_with_fitted_extent_is_refused():
    # A vertex at depth exactly 0 has no finite tangent: the fit cannot bound
    # its shadow, so it asks for an explicit extent (and names the argument).
    scene = ss.Scene(occluders=[_cut_quad()], receivers=[scenes.floor()])
    with pytest.raises(ValueError, match="occluders.*extent="):
        ss.soft_shadow_map(scene, scenes.default_light(), resolution=16)
