"""Properties over random scenes and lights (hypothesis; derandomized so CI
sees the same examples every run).

- Visibility is finite and in [0, 1], for every method.
- Adding occluder texels where the maps were empty never raises visibility,
  for every map method but pcss and bitmask's connected quads (the SSM adds
  non-negative terms to clamped sums, in a fixed order, and float addition is
  monotone; the bitmask's flat patches OR more bits);
  adding any occluder never raises it for `exact` (its rays only gain hits,
  with the same deterministic jitter). Adding an occluder in front of
  another can raise it for the map methods -- see test_occluder_hiding_
  another_can_lighten_the_map_methods.
- Moving scene and light together changes nothing; neither does scaling
  depths and light size by a power of two (exact in floating point).
- The two-pass SSM is not bounded below by `exact`: it is darker where
  micro-patches at different depths overlap in back-projection (summed,
  §4.1.2) and where the map dilates a silhouette by up to half a texel,
  whose back-projection covers k hw / L of the light (k = z_R z_O / (z_R -
  z_O): large for occluders near the receiver). Measured on 150 random
  scenes of 1-3 tilted plates (32², 1024-sample `exact`): at most 0.63
  darker. Where the discretization is exact (texel-aligned plates parallel
  to the light) the bound is exact too: the SSM is darker than the truth by
  the overlap of the plates' back-projections, no more (tested below).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import softshadow as ss
from hard_cases import plate as closed
from hard_cases.common import BACKENDS, MAP_METHODS, METHODS, assert_visibility, has_option
from softshadow import scenes

SETTINGS = settings(
    max_examples=50, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow], database=None
)

coords = st.floats(-1.0, 1.0)


@st.composite
def plate(draw):
    c = (draw(coords), draw(st.floats(0.3, 3.5)), draw(coords))
    v, f = scenes.quad(c, draw(st.floats(0.05, 0.6)))
    a = draw(st.floats(-0.6, 0.6))  # tilt about x
    rot = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    return (v - c) @ rot.T + c, f


@st.composite
def scene_and_light(draw):
    plates = draw(st.lists(plate(), min_size=1, max_size=3))
    size = (draw(st.floats(0.05, 2.0)), draw(st.floats(0.05, 2.0)))
    tilt = (draw(st.floats(-0.2, 0.2)), draw(st.floats(-0.2, 0.2)))
    light = ss.RectLight(center=(0, 4, 0), normal=(tilt[0], -1, tilt[1]), up=(0, 0, 1), size=size)
    return plates, light


def _kw(method, backend, passes=None):
    kw = dict(method=method, backend=backend, **({"samples": 64} if has_option(method, "samples") else {}))
    return kw | ({"passes": passes} if passes is not None and has_option(method, "passes") else {})


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(scene_and_light(), st.sampled_from(METHODS), st.sampled_from(BACKENDS), st.integers(1, 3))
def test_visibility_is_finite_and_in_unit_interval(sl, method, backend, passes):
    plates, light = sl
    scene = ss.Scene(occluders=plates, receivers=[scenes.floor()])
    sm = ss.soft_shadow_map(scene, light, resolution=24, **_kw(method, backend, passes))
    assert_visibility(sm.visibility)
    np.testing.assert_array_equal(sm.visibility[~np.isfinite(sm.receiver_depth)], 1.0)


@st.composite
def depth_maps(draw):
    h, w = draw(st.integers(1, 20)), draw(st.integers(1, 20))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    rec = rng.uniform(3.0, 5.0, (h, w)).astype(np.float32)
    rec[rng.random((h, w)) < 0.1] = np.inf
    occ = np.where(rng.random((h, w)) < 0.3, rng.uniform(0.5, 4.5, (h, w)), np.inf).astype(np.float32)
    added = np.where(rng.random((h, w)) < 0.3, rng.uniform(0.5, 4.5, (h, w)), np.inf).astype(np.float32)
    size = (draw(st.floats(0.05, 3.0)), draw(st.floats(0.05, 3.0)))
    ext = (draw(st.floats(0.05, 2.0)), draw(st.floats(0.05, 2.0)))
    return occ, rec, added, size, ext


# Not pcss: an added blocker moves its mean blocker depth, and a farther mean
# shrinks the filter box, which can let more light through (Fernando's one
# average depth per receiver; found by this very property). Bitmask with its
# default closed gaps neither: an added texel connects to its neighbours and
# moves their quads' corners (the surface rebuilt from the samples changes,
# say from a slope to a ridge), which can shrink a neighbour's quad (found by
# this property on random depth maps). Its flat micro-patches (gaps="open")
# only gain bits, and are tested here.
MONOTONE_MAP_METHODS = tuple(m for m in MAP_METHODS if m != "pcss")


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(depth_maps(), st.sampled_from(MONOTONE_MAP_METHODS), st.sampled_from(BACKENDS))
def test_occluders_in_empty_texels_never_raise_visibility(maps, method, backend):
    occ, rec, added, size, ext = maps
    more = np.where(np.isfinite(occ), occ, added)  # only empty texels change
    kw = dict(light_size=size, extent=ext, **_kw(method, backend))
    if method == "bitmask":
        kw["method"] = ss.Bitmask(samples=kw.pop("samples"), gaps="open")
    before = ss.soft_shadow_map_from_depth(occ, rec, **kw).visibility
    after = ss.soft_shadow_map_from_depth(more, rec, **kw).visibility
    assert_visibility(after)
    assert np.all(after <= before), float((after - before).max())


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(scene_and_light(), plate(), st.sampled_from(BACKENDS))
def test_any_occluder_never_raises_exact_visibility(sl, extra, backend):
    plates, light = sl
    kw = dict(resolution=24, extent=1.0, method="exact", samples=64, backend=backend)
    before = ss.soft_shadow_map(ss.Scene(occluders=plates, receivers=[scenes.floor()]), light, **kw)
    after = ss.soft_shadow_map(ss.Scene(occluders=plates + [extra], receivers=[scenes.floor()]), light, **kw)
    assert np.all(after.visibility <= before.visibility)


def test_occluder_hiding_another_can_lighten_the_map_methods():
    # A large plate at depth 3.5 (near the floor) and a smaller one at depth 1
    # above its middle: the nearer plate replaces the farther one's texels in
    # the front map, and a nearer micro-patch back-projects smaller (k falls
    # with z_O), so the sums under it fall. Documented, not a bug of this code.
    light = scenes.default_light()
    big = scenes.quad((0.0, 0.5, 0.0), 0.6)
    small = scenes.quad((0.0, 3.0, 0.0), 0.08)
    kw = dict(resolution=32, extent=0.3, passes=1)
    one = ss.soft_shadow_map(ss.Scene(occluders=[big], receivers=[scenes.floor()]), light, **kw).visibility
    two = ss.soft_shadow_map(ss.Scene(occluders=[big, small], receivers=[scenes.floor()]), light, **kw).visibility
    assert (two - one).max() > 0.05
    ex = dict(kw, method="exact", samples=256)
    one = ss.soft_shadow_map(ss.Scene(occluders=[big], receivers=[scenes.floor()]), light, **ex).visibility
    two = ss.soft_shadow_map(ss.Scene(occluders=[big, small], receivers=[scenes.floor()]), light, **ex).visibility
    assert np.all(two <= one)


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(
    scene_and_light(),
    st.sampled_from(METHODS),
    st.sampled_from(BACKENDS),
    st.tuples(*[st.floats(-1e3, 1e3)] * 3),
)
def test_moving_scene_and_light_together_changes_nothing(sl, method, backend, offset):
    plates, light = sl
    kw = dict(resolution=24, **_kw(method, backend))
    base = ss.soft_shadow_map(ss.Scene(occluders=plates, receivers=[scenes.floor()]), light, **kw)
    off = np.asarray(offset)
    moved = ss.Scene(
        occluders=[(v + off, f) for v, f in plates], receivers=[(scenes.floor()[0] + off, scenes.floor()[1])]
    )
    light2 = ss.RectLight(center=np.add(light.center, off), normal=light.normal, up=light.up, size=light.size)
    sm = ss.soft_shadow_map(moved, light2, **kw)
    # Up to texel sampling: rounding of the moved vertices (1e-13 relative)
    # may move a rasterized edge across a texel center or a ray past an edge.
    d = np.abs(sm.visibility - base.visibility)
    assert d.mean() <= 1e-3, (d.mean(), d.max())


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(depth_maps(), st.sampled_from(MAP_METHODS), st.sampled_from(BACKENDS), st.integers(-80, 80))
def test_power_of_two_scale_changes_nothing(maps, method, backend, k):
    occ, rec, _, size, ext = maps
    s = 2.0**k
    kw = dict(extent=ext, **_kw(method, backend))
    base = ss.soft_shadow_map_from_depth(occ, rec, light_size=size, **kw).visibility
    scaled = ss.soft_shadow_map_from_depth(
        (occ * np.float32(s)).astype(np.float32),
        (rec * np.float32(s)).astype(np.float32),
        light_size=(size[0] * s, size[1] * s),
        **kw,
    ).visibility
    np.testing.assert_array_equal(scaled, base)


@st.composite
def two_aligned_plates(draw):
    # Two texel-aligned rectangles at different depths, disjoint in the map
    # (so both are in the front layer), on a 32 x 32 map over extent 0.5.
    n, t = 32, 0.5
    edges = (np.arange(n + 1) / n * 2 - 1) * t

    def rect(cols, rows):
        i0, i1 = sorted(draw(st.lists(st.integers(*cols), min_size=2, max_size=2, unique=True)))
        j0, j1 = sorted(draw(st.lists(st.integers(*rows), min_size=2, max_size=2, unique=True)))
        return (edges[i0], edges[i1], edges[j0], edges[j1])

    a = rect((0, 16), (0, 32))  # left half of the map
    b = rect((16, 32), (0, 32))  # right half
    za, zb = draw(st.floats(0.5, 3.5)), draw(st.floats(0.5, 3.5))
    size = (draw(st.floats(0.2, 3.0)), draw(st.floats(0.2, 3.0)))
    return a, za, b, zb, size


@pytest.mark.gpu  # its examples draw backend="gpu" too
@SETTINGS
@given(two_aligned_plates(), st.sampled_from(BACKENDS))
def test_ssm_is_darker_than_the_truth_by_the_back_projections_overlap(case, backend):
    a, za, b, zb, (lx, ly) = case
    n, zr = 32, 4.0
    x = closed.centers(n, 0.5)
    y = closed.centers(n, 0.5)[::-1]
    occ = np.full((n, n), np.inf, np.float32)
    for (x0, x1, y0, y1), z in ((a, za), (b, zb)):
        inside = ((x > x0) & (x < x1))[None, :] & ((y > y0) & (y < y1))[:, None]
        occ[inside] = z
    rec = np.full((n, n), zr, np.float32)
    ba = closed.backprojection(x[None, :], y[:, None], a, float(np.float32(za)), zr, lx, ly)
    bb = closed.backprojection(x[None, :], y[:, None], b, float(np.float32(zb)), zr, lx, ly)
    sa, sb = closed.area(ba, lx, ly), closed.area(bb, lx, ly)
    both = closed.area(closed.intersection(ba, bb), lx, ly)
    truth = 1 - (sa + sb - both)
    kw = dict(light_size=(lx, ly), extent=0.5, backend=backend)
    ssm = ss.soft_shadow_map_from_depth(occ, rec, method="ssm", **kw).visibility
    # The SSM sums the two (clamped): darker than the truth by the overlap.
    np.testing.assert_allclose(ssm, 1 - np.minimum(1, sa + sb), atol=closed.SSM_BOUND)
    assert np.all(truth - ssm <= both + closed.SSM_BOUND)
    # The bitmask ORs: the union, to its pattern (8 edges: twice the bound).
    bm = ss.soft_shadow_map_from_depth(occ, rec, method="bitmask", samples=256, **kw).visibility
    assert np.abs(bm - truth).max() <= 2 * closed.BITMASK_BOUND
