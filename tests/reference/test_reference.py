"""Tests of softshadow.reference (Mitsuba 3 ground truth) and softshadow.metrics.

The reference is checked against the closed-form visibility of a square plate
parallel to a rectangular light: seen from a point P, the plate shadows the
light where the plate's back-projection from P onto the light plane (a
homothety of centre P) overlaps the light rectangle; both are axis-aligned
rectangles in the light's (u, v) frame, so the overlap is a product of
interval overlaps.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import softshadow
from softshadow import metrics, reference

# --------------------------------------------------------------------------
# Helpers: scene set-up and closed forms
# --------------------------------------------------------------------------

LIGHT_CENTER = np.array([0.0, 4.0, 0.0])
# Light 4 units above the floor y = 0, facing down. Its frame is
# n = (0,-1,0), v = (0,0,1), u = n x v = (-1,0,0): +u is world -x.
DOWN = (0.0, -1.0, 0.0)
UP_Z = (0.0, 0.0, 1.0)
U = np.array([-1.0, 0.0, 0.0])
V = np.array([0.0, 0.0, 1.0])
N = np.array([0.0, -1.0, 0.0])
FLOOR_DEPTH = 4.0


def make_light(size=(1.0, 1.0), normal=DOWN):
    """A light object with the attributes the reference module expects."""
    return SimpleNamespace(center=tuple(LIGHT_CENTER), normal=normal, up=UP_Z, size=size)


def plate(depth, a_range, b_range):
    """Quad parallel to the light at planar ``depth``, spanning a_range x b_range
    in the light's (u, v) coordinates, as a (vertices, faces) pair."""
    (a0, a1), (b0, b1) = a_range, b_range
    corners = [(a0, b0), (a1, b0), (a1, b1), (a0, b1)]
    vertices = np.array([LIGHT_CENTER + depth * N + a * U + b * V for a, b in corners])
    return vertices, np.array([[0, 1, 2], [0, 2, 3]])


def floor_points(a_values, b_values):
    """Floor points (depth 4) at light-frame coordinates a (along u), b (along v)."""
    a, b = np.meshgrid(a_values, b_values, indexing="ij")
    a, b = a.ravel(), b.ravel()
    return LIGHT_CENTER + FLOOR_DEPTH * N + a[:, None] * U + b[:, None] * V


def interval_overlap(lo, hi, half_width):
    """Length of [lo, hi] intersected with [-half_width, half_width]."""
    return np.clip(np.minimum(hi, half_width) - np.maximum(lo, -half_width), 0.0, None)


def exact_visibility(points, light_size, plate_depth, a_range, b_range):
    """Closed-form visibility of a parallel plate, for points beyond the plate.

    The ray from P (planar depth h) through a plate point X (depth d) meets the
    light plane at Q = P + s (X - P), s = h / (h - d), so the plate maps to an
    axis-aligned rectangle whose overlap with the light is occluded.
    """
    rel = points - LIGHT_CENTER
    pa, pb, depth = rel @ U, rel @ V, rel @ N
    scale = depth / (depth - plate_depth)
    sx, sy = light_size
    overlap_a = interval_overlap(pa + scale * (a_range[0] - pa), pa + scale * (a_range[1] - pa), sx / 2)
    overlap_b = interval_overlap(pb + scale * (b_range[0] - pb), pb + scale * (b_range[1] - pb), sy / 2)
    return 1.0 - overlap_a * overlap_b / (sx * sy)


@pytest.fixture(scope="module")
def mitsuba_reference():
    """The reference module, skipping when Mitsuba is not installed."""
    pytest.importorskip("mitsuba")
    pytest.importorskip("drjit")
    return reference


# --------------------------------------------------------------------------
# Reference visibility against the closed form
# --------------------------------------------------------------------------

# (light size, plate depth, plate a-range, plate b-range, (a, b) region of
# floor points covering the whole soft shadow and some lit floor)
PLATE_CASES = {
    # The paper-like set-up: plate of side 0.5 half-way to the floor. Its
    # back-projection from any floor point is exactly as large as the light,
    # so the umbra shrinks to the point under the centre.
    "square-light-half-way": ((1.0, 1.0), 2.0, (-0.25, 0.25), (-0.25, 0.25), ((-1.5, 1.5), (-1.5, 1.5))),
    # Non-square light and a plate nearer the floor, off-centre: a real umbra,
    # and a swap of the u and v extents would change the penumbrae.
    # Umbra: a in [0.18, 0.35], b in [-0.38, 0.12]; penumbra up to
    # a in (-0.32, 0.85), b in (-0.55, 0.28).
    "wide-light-low-plate": ((1.5, 0.5), 3.0, (-0.05, 0.45), (-0.35, 0.15), ((-0.5, 1.0), (-0.7, 0.45))),
}


@pytest.mark.parametrize("case", sorted(PLATE_CASES))
def test_visibility_matches_closed_form(mitsuba_reference, case):
    light_size, depth, a_range, b_range, region = PLATE_CASES[case]
    light = make_light(light_size)
    # 21 x 21 points; the first case's grid contains 0, its umbra point.
    points = floor_points(np.linspace(*region[0], 21), np.linspace(*region[1], 21))
    exact = exact_visibility(points, light_size, depth, a_range, b_range)
    # The point set must span umbra, penumbra and lit regions.
    assert np.any(exact == 1.0) and np.count_nonzero((exact > 0) & (exact < 1)) > 100
    assert exact.min() < 0.05

    estimate = mitsuba_reference.visibility_at_points(
        [plate(depth, a_range, b_range)], light, points, samples=1024, seed=3
    )

    assert estimate.shape == (len(points),) and estimate.dtype == np.float32
    # Error bound of jittered stratified sampling on the 32 x 32 grid: a
    # stratum contributes variance only if an edge of the back-projected plate
    # cuts it. The edges are parallel to the grid lines and, in both cases, at
    # most one edge per axis lies inside the light, so at most 2 x 32 = 64 of
    # the 1024 strata are cut. Each contributes a Bernoulli bounded by 1/1024,
    # so by Hoeffding P(|err| > t) <= 2 exp(-2 t^2 1024^2 / 64): for t = 0.02
    # that is 4e-6 per point, 2e-3 for the 441 points. The standard deviation
    # is at most sqrt(64 / 4) / 1024 = 0.0039 for penumbra points and 0 for
    # lit and umbra points, so the mean absolute error stays below 0.005.
    error = np.abs(estimate - exact)
    assert error.max() < 0.02
    assert error.mean() < 0.005
    # Fully lit points have no occluded sample at all.
    assert np.all(estimate[exact == 1.0] == 1.0)


def test_umbra_and_lit_points_are_exact(mitsuba_reference):
    light_size, depth, a_range, b_range, _ = PLATE_CASES["wide-light-low-plate"]
    # In the middle of the umbra, and far away in the lit region.
    points = floor_points([0.27, 3.0], [-0.13])
    exact = exact_visibility(points, light_size, depth, a_range, b_range)
    np.testing.assert_array_equal(exact, [0.0, 1.0])
    estimate = mitsuba_reference.visibility_at_points(
        [plate(depth, a_range, b_range)], make_light(light_size), points, samples=256
    )
    np.testing.assert_array_equal(estimate, [0.0, 1.0])


def test_non_square_sample_counts(mitsuba_reference):
    occluders = [plate(2.0, (-0.25, 0.25), (-0.25, 0.25))]
    points = floor_points([0.0, 0.5, 3.0], [0.0])
    exact = exact_visibility(points, (1.0, 1.0), 2.0, (-0.25, 0.25), (-0.25, 0.25))
    for samples in (7, 12, 1000):  # prime (1 x 7 strips), 4 x 3, 40 x 25
        estimate = mitsuba_reference.visibility_at_points(occluders, make_light(), points, samples=samples)
        # Visibility is a count of unblocked samples over K.
        np.testing.assert_allclose(estimate * samples, np.round(estimate * samples), atol=1e-3)
        assert estimate[2] == 1.0
        # The shadow edge (perpendicular to u) cuts at most one column of
        # strata, and there are at least 7 columns along u: error <= 1/7.
        assert abs(estimate[1] - exact[1]) <= 1.0 / 7.0 + 1e-6


def test_seed_determinism_and_batching(mitsuba_reference, monkeypatch):
    occluders = [plate(2.0, (-0.25, 0.25), (-0.25, 0.25))]
    # Off the stratum boundaries, so that the jitter matters.
    points = floor_points(np.linspace(-1, 1, 9) + 0.03, np.linspace(-1, 1, 9) + 0.01)

    def run(seed):
        return mitsuba_reference.visibility_at_points(occluders, make_light(), points, samples=64, seed=seed)

    first = run(7)
    np.testing.assert_array_equal(first, run(7))
    assert np.any(first != run(8))  # penumbra points see different jitter
    # Splitting the rays into many batches must not change the result.
    monkeypatch.setattr(mitsuba_reference._rays, "MAX_RAYS_PER_BATCH", 100)
    np.testing.assert_array_equal(first, run(7))


def test_mesh_inputs(mitsuba_reference):
    trimesh = pytest.importorskip("trimesh")
    vertices, faces = plate(2.0, (-0.25, 0.25), (-0.25, 0.25))
    points = floor_points(np.linspace(-1, 1, 7), [0.0, 0.3])
    light = make_light()
    as_pair = mitsuba_reference.visibility_at_points([(vertices, faces)], light, points, samples=64)
    as_trimesh = mitsuba_reference.visibility_at_points(
        [trimesh.Trimesh(vertices, faces, process=False)], light, points, samples=64
    )
    np.testing.assert_array_equal(as_pair, as_trimesh)
    # No occluder (or only empty meshes): everything is lit.
    empty = (np.zeros((0, 3)), np.zeros((0, 3), dtype=int))
    for occluders in ([], [empty]):
        lit = mitsuba_reference.visibility_at_points(occluders, light, points, samples=16)
        np.testing.assert_array_equal(lit, 1.0)
    assert mitsuba_reference.visibility_at_points([], light, np.zeros((0, 3))).shape == (0,)


def test_reference_scene_reuse_and_stats(mitsuba_reference):
    scene = mitsuba_reference.ReferenceScene([plate(2.0, (-0.25, 0.25), (-0.25, 0.25))])
    assert scene.variant == mitsuba_reference.variant()
    assert (scene.n_meshes, scene.n_triangles) == (1, 2)
    assert scene.last_stats is None
    points = floor_points(np.linspace(-1, 1, 16), np.linspace(-1, 1, 16))
    first = scene.visibility(make_light(), points, samples=64)
    second = scene.visibility(make_light(), points, samples=64)
    np.testing.assert_array_equal(first, second)
    stats = scene.last_stats
    assert (stats.n_points, stats.samples, stats.n_rays) == (256, 64, 256 * 64)
    assert 0.0 < stats.trace_seconds <= stats.total_seconds
    assert stats.rays_per_second > 0.0
    # The convenience functions accept a built scene in place of meshes.
    np.testing.assert_array_equal(
        mitsuba_reference.visibility_at_points(scene, make_light(), points, samples=64), first
    )
    shadow_map = light_view_map(make_light(), size=8)
    np.testing.assert_array_equal(
        mitsuba_reference.reference_map(shadow_map, scene, samples=16),
        mitsuba_reference.reference_map(shadow_map, [plate(2.0, (-0.25, 0.25), (-0.25, 0.25))], samples=16),
    )


def test_variant_is_active(mitsuba_reference):
    import mitsuba as mi

    chosen = mitsuba_reference.variant()
    assert chosen in ("llvm_ad_rgb", "scalar_rgb")
    assert mi.variant() == chosen


def test_scalar_variant_agrees(mitsuba_reference):
    """The scalar fallback (forced in a fresh process) gives the same answer."""
    script = textwrap.dedent(
        """
        import sys, numpy as np
        from types import SimpleNamespace
        from softshadow import reference
        light = SimpleNamespace(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 1))
        plate = (np.array([[-.25, 2, -.25], [.25, 2, -.25], [.25, 2, .25], [-.25, 2, .25]]),
                 np.array([[0, 1, 2], [0, 2, 3]]))
        points = np.array([[0, 0, 0], [0.3, 0, 0.1], [-0.6, 0, 0.2], [3, 0, 0]])
        v = reference.visibility_at_points([plate], light, points, samples=64, seed=5)
        print(reference.variant(), *v.tolist())
        """
    )
    env = dict(os.environ, SOFTSHADOW_MITSUBA_VARIANT="scalar_rgb")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(softshadow.__file__).parent.parent)] + sys.path)
    result = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    name, *values = result.stdout.split()
    assert name == "scalar_rgb"
    points = np.array([[0, 0, 0], [0.3, 0, 0.1], [-0.6, 0, 0.2], [3, 0, 0]], dtype=float)
    here = mitsuba_reference.visibility_at_points(
        [plate(2.0, (-0.25, 0.25), (-0.25, 0.25))], make_light(), points, samples=64, seed=5
    )
    # Same seed, same rays: only rays grazing an edge may differ.
    np.testing.assert_allclose(np.array(values, dtype=float), here, atol=2 / 64)


# --------------------------------------------------------------------------
# Light-view reference maps and the (u, v) orientation
# --------------------------------------------------------------------------


def light_view_map(light, size=32, extent=(0.5, 0.5)):
    """A shadow-map-like object whose receiver is the floor (depth 4)."""
    depth = np.full((size, size), FLOOR_DEPTH, dtype=np.float32)
    return SimpleNamespace(light=light, extent=extent, receiver_depth=depth)


def texel_points(shadow_map):
    """Texel world points by the project convention, computed independently."""
    height, width = shadow_map.receiver_depth.shape
    tx, ty = shadow_map.extent
    j, i = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    x = (-1 + 2 * (i + 0.5) / width) * tx
    y = (1 - 2 * (j + 0.5) / height) * ty
    depth = shadow_map.receiver_depth.astype(float)
    return LIGHT_CENTER + depth[..., None] * (N + x[..., None] * U + y[..., None] * V)


def test_reference_map_matches_closed_form(mitsuba_reference):
    light_size, depth, a_range, b_range, _ = PLATE_CASES["wide-light-low-plate"]
    shadow_map = light_view_map(make_light(light_size))
    points = texel_points(shadow_map).reshape(-1, 3)
    exact = exact_visibility(points, light_size, depth, a_range, b_range).reshape(32, 32)
    result = mitsuba_reference.reference_map(shadow_map, [plate(depth, a_range, b_range)], samples=1024)
    assert result.shape == (32, 32) and result.dtype == np.float32
    assert np.abs(result - exact).max() < 0.02  # bound justified above


@pytest.mark.parametrize("axis", ["u", "v"])
def test_reference_map_orientation(mitsuba_reference, axis):
    """A plate offset along +u (+v) shadows texels with x > 0 (y > 0)."""
    offset, centred = (0.5, 0.8), (-0.25, 0.25)
    a_range, b_range = (offset, centred) if axis == "u" else (centred, offset)
    shadow_map = light_view_map(make_light())
    result = mitsuba_reference.reference_map(shadow_map, [plate(2.0, a_range, b_range)], samples=64)
    # x > 0 is the right half of the columns; y > 0 is the top half of rows.
    positive, negative = (result[:, 16:], result[:, :16]) if axis == "u" else (result[:16], result[16:])
    assert np.all(negative == 1.0)
    # The back-projected plate is 0.6 wide along u: at most 60% occluded.
    assert positive.min() < 0.6


def test_reference_map_skips_texels_without_receiver(mitsuba_reference):
    shadow_map = light_view_map(make_light(), size=8, extent=(0.1, 0.1))
    shadow_map.receiver_depth[:, :4] = np.inf
    # A plate covering the whole view: every receiver texel is in umbra.
    result = mitsuba_reference.reference_map(shadow_map, [plate(2.0, (-2, 2), (-2, 2))], samples=16)
    np.testing.assert_array_equal(result[:, :4], 1.0)
    np.testing.assert_array_equal(result[:, 4:], 0.0)


def test_reference_map_validation():
    shadow_map = light_view_map(make_light(), size=4)
    shadow_map.receiver_depth[0, 0] = np.nan
    with pytest.raises(ValueError, match="receiver_depth"):
        reference.reference_map(shadow_map, [])
    shadow_map.receiver_depth[0, 0] = -1.0
    with pytest.raises(ValueError, match="receiver_depth"):
        reference.reference_map(shadow_map, [])
    with pytest.raises(TypeError, match="extent"):
        no_extent = SimpleNamespace(light=make_light(), receiver_depth=np.ones((2, 2)))
        reference.reference_map(no_extent, [])
    bad_extent = light_view_map(make_light(), size=4, extent=(0.5, 0.0))
    with pytest.raises(ValueError, match="extent"):
        reference.reference_map(bad_extent, [])


# --------------------------------------------------------------------------
# Input validation (no Mitsuba needed: checked before the scene is built)
# --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("points", "samples", "light", "error", "match"),
    [
        (np.zeros((3, 2)), 16, make_light(), ValueError, "points"),
        (np.array([[0.0, np.nan, 0.0]]), 16, make_light(), ValueError, "points"),
        (np.array([[0.0, np.inf, 0.0]]), 16, make_light(), ValueError, "points"),
        (np.zeros((1, 3)), 0, make_light(), ValueError, "samples"),
        (np.zeros((1, 3)), 16.0, make_light(), TypeError, "samples"),
        (np.zeros((1, 3)), True, make_light(), TypeError, "samples"),
        (np.zeros((1, 3)), 16, make_light(size=(1.0, -1.0)), ValueError, "light.size"),
        (np.zeros((1, 3)), 16, make_light(normal=(0.0, 0.0, 1.0)), ValueError, "light.up"),
        (np.zeros((1, 3)), 16, SimpleNamespace(center=(0, 0, 0)), TypeError, "light"),
    ],
)
def test_visibility_validation(points, samples, light, error, match):
    with pytest.raises(error, match=match):
        reference.visibility_at_points([], light, points, samples=samples)


def test_mesh_validation():
    vertices, faces = plate(2.0, (-0.25, 0.25), (-0.25, 0.25))
    with pytest.raises(ValueError, match=r"occluders\[0\]"):
        reference.ReferenceScene([(vertices, faces + 10)])
    with pytest.raises(TypeError, match=r"occluders\[0\]"):
        reference.ReferenceScene([vertices])
    with pytest.raises(TypeError, match="occluders"):
        reference.ReferenceScene((vertices, faces)[0])


def test_missing_mitsuba_message(monkeypatch):
    """Without Mitsuba, the error says how to install it."""
    monkeypatch.setitem(sys.modules, "mitsuba", None)  # makes `import mitsuba` fail
    with pytest.raises(ImportError, match=r"pip install softshadow\[reference\]"):
        reference._import_mitsuba()


def test_importing_softshadow_does_not_import_mitsuba():
    package_root = Path(softshadow.__file__).parent.parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(package_root)] + sys.path))
    script = (
        "import sys, softshadow, softshadow.metrics, softshadow.reference; "
        "assert 'mitsuba' not in sys.modules and 'drjit' not in sys.modules"
    )
    result = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr


# --------------------------------------------------------------------------
# Eye-view render
# --------------------------------------------------------------------------


def render_plate_scene(module, normal=DOWN):
    """33 x 33 view of the floor under the low plate, from above and behind.

    The camera looks at the origin, which is in the plate's umbra; the floor
    points (+-1.5, 0, 0) are fully lit and project onto the centre row at
    horizontal NDC -+1.5 / (|origin| tan 22.5 deg) = -+0.46, i.e. columns 8
    and 24.
    """
    depth, side = 3.0, (-0.25, 0.25)
    floor = (
        np.array([[-3.0, 0, -3.0], [3.0, 0, -3.0], [3.0, 0, 3.0], [-3.0, 0, 3.0]]),
        np.array([[0, 1, 2], [0, 2, 3]]),
    )
    return module.render_image(
        [plate(depth, side, side)],
        [floor],
        make_light(normal=normal),
        camera_origin=(0.0, 5.0, 6.0),
        camera_target=(0.0, 0.0, 0.0),
        width=33,
        height=33,
        spp=16,
    )


def test_render_image_shadow(mitsuba_reference):
    image = render_plate_scene(mitsuba_reference)
    assert image.shape == (33, 33, 3) and image.dtype == np.float32
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    umbra = image[16, 16].mean()
    lit = min(image[16, 8].mean(), image[16, 24].mean())
    # Direct lighting only: the umbra receives nothing at all.
    assert lit > 0.01
    assert umbra < 0.1 * lit


def test_render_image_light_emits_along_normal(mitsuba_reference):
    # Flipped light: it now shines upward, away from the floor.
    image = render_plate_scene(mitsuba_reference, normal=(0.0, 1.0, 0.0))
    assert image[16, 8].max() == 0.0 and image[16, 24].max() == 0.0


# --------------------------------------------------------------------------
# Metrics
# --------------------------------------------------------------------------

# Occlusion 1 - V_REF = [[0, 5e-4, 0.5], [1, 0, 0.8]]: with the default
# threshold 1e-3, the shadow is the three texels 0.5, 0.0 and 0.2.
V_REF = np.array([[1.0, 0.9995, 0.5], [0.0, 1.0, 0.2]])
V_EST = np.array([[0.7, 0.5, 0.6], [0.1, 1.0, 0.2]])
# |V_EST - V_REF| = [[0.3, 0.4995, 0.1], [0.1, 0, 0]]


def test_shadow_error_hand_computed():
    assert metrics.shadow_error(V_EST, V_REF) == pytest.approx(0.2 / 3)
    # Threshold 0 also counts the 5e-4-occluded texel; 0.6 keeps occlusion 1 and 0.8.
    assert metrics.shadow_error(V_EST, V_REF, threshold=0.0) == pytest.approx(0.6995 / 4)
    assert metrics.shadow_error(V_EST, V_REF, threshold=0.6) == pytest.approx(0.1 / 2)
    assert metrics.shadow_error(V_REF, V_REF) == 0.0
    np.testing.assert_array_equal(metrics.shadow_mask(V_REF), [[False, False, True], [True, False, True]])


def test_shadow_error_empty_shadow_is_zero():
    lit = np.ones((4, 4))
    assert metrics.shadow_error(np.zeros((4, 4)), lit) == 0.0
    assert metrics.compare(np.zeros((4, 4)), lit)["shadow_texels"] == 0


def test_rmse_max_and_masks():
    squares = 0.3**2 + 0.4995**2 + 0.1**2 + 0.1**2
    assert metrics.rmse(V_EST, V_REF) == pytest.approx(np.sqrt(squares / 6))
    assert metrics.max_error(V_EST, V_REF) == pytest.approx(0.4995)
    mask = np.array([[True, False, True], [False, False, False]])
    assert metrics.rmse(V_EST, V_REF, mask=mask) == pytest.approx(np.sqrt(0.1 / 2))
    assert metrics.max_error(V_EST, V_REF, mask=mask) == pytest.approx(0.3)
    nothing = np.zeros((2, 3), dtype=bool)
    assert metrics.rmse(V_EST, V_REF, mask=nothing) == 0.0
    assert metrics.max_error(V_EST, V_REF, mask=nothing) == 0.0


def test_compare():
    result = metrics.compare(V_EST, V_REF)
    assert set(result) == {"error", "rmse", "max", "acne", "leak", "shadow_texels"}
    assert result["acne"] == pytest.approx(2 / 6) and result["leak"] == pytest.approx(1 / 6)
    assert result["error"] == pytest.approx(0.2 / 3)
    assert result["rmse"] == pytest.approx(metrics.rmse(V_EST, V_REF))
    assert result["max"] == pytest.approx(0.4995)
    assert result["shadow_texels"] == 3 and isinstance(result["shadow_texels"], int)


def test_acne_and_leak_rates_hand_computed():
    # Lit in the reference: (0, 0) and (0, 1) darkened by 0.3 and 0.4995
    # (acne), (1, 1) not; umbra: (1, 0) lightened by 0.1 (a leak).
    assert metrics.acne_leak(V_EST, V_REF) == pytest.approx((2 / 6, 1 / 6))
    # A margin of exactly 0.05 is not acne, a hair more is.
    ref = np.ones((1, 2))
    assert metrics.acne_leak(np.array([[0.95, 0.9499]]), ref) == (0.5, 0.0)
    # Over a mask: the rate is of the texels selected.
    mask = np.array([[False, False, False], [True, True, False]])
    assert metrics.acne_leak(V_EST, V_REF, mask=mask) == (0.0, 0.5)
    assert metrics.acne_leak(V_EST, V_REF, mask=np.zeros((2, 3), dtype=bool)) == (0.0, 0.0)
    assert metrics.acne_leak(V_REF, V_REF) == (0.0, 0.0)


@pytest.mark.parametrize(
    "function", [metrics.shadow_error, metrics.rmse, metrics.max_error, metrics.compare, metrics.acne_leak]
)
def test_metrics_reject_bad_input(function):
    with_nan = V_EST.copy()
    with_nan[0, 1] = np.nan
    with pytest.raises(ValueError, match=r"^v contains"):
        function(with_nan, V_REF)
    with pytest.raises(ValueError, match=r"^v_ref contains"):
        function(V_EST, np.where(V_REF > 0.9, np.inf, V_REF))
    with pytest.raises(ValueError, match="shape"):
        function(V_EST, V_REF[:, :2])


def test_metrics_reject_bad_mask_and_threshold():
    with pytest.raises(ValueError, match="mask"):
        metrics.rmse(V_EST, V_REF, mask=np.ones((3, 2), dtype=bool))
    with pytest.raises(TypeError, match="mask"):
        metrics.max_error(V_EST, V_REF, mask=np.ones((2, 3)))
    for threshold in (-0.1, 1.0, np.nan):
        with pytest.raises(ValueError, match="threshold"):
            metrics.shadow_error(V_EST, V_REF, threshold=threshold)
