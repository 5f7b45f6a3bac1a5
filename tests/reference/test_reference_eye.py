"""Tests of softshadow.reference.render_visibility (eye-view Mitsuba reference)
and softshadow.metrics.compare_images.

Every scene has a closed form or a geometric certainty to check against:

* a square plate parallel to a rectangular light and to the floor: seen from a
  floor point P, the plate hides the part of the light covered by its
  back-projection from P (a homothety of centre P), an axis-aligned rectangle
  in the light's (u, v) frame, so the visibility is 1 minus a product of two
  interval overlaps;
* the same under a directional light travelling straight down: the plate
  blocks the directions n + x u + y v whose ray from P meets it, again an
  axis-aligned rectangle in (x, y), so the visibility is 1 minus a product of
  two overlaps of tangent intervals;
* a convex closed mesh: a face with the whole light behind its plane is in
  its own umbra, one with the whole light in front of it is fully lit.

Error bound of the stratified estimates (used below). With K = 256 samples
on a 16 x 16 grid, a stratum adds variance only if an edge of the blocked
rectangle cuts it; in every scene here the blocked rectangle is wider than
the light along both axes, so at most one edge per axis lies inside and at
most 2 x 16 = 32 strata are cut. Each contributes a Bernoulli bounded by
1/256, so by Hoeffding P(|err| > t) <= 2 exp(-2 t^2 256^2 / 32): for t = 0.06
that is 8e-7 per pixel, 2.4e-3 for 3072 pixels. The standard deviation is at
most sqrt(32 / 4) / 256 = 0.011 in the penumbra and 0 elsewhere.
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

import softshadow as ss
from softshadow import metrics, reference

SAMPLES = 256
MAX_ERROR = 0.06  # Hoeffding bound of the module docstring
MEAN_ERROR = 0.011  # standard deviation bound of the module docstring


@pytest.fixture(scope="module")
def eye():
    """The reference package, skipping when Mitsuba or trimesh is missing."""
    pytest.importorskip("mitsuba")
    pytest.importorskip("drjit")
    return reference


@pytest.fixture(scope="module")
def creation():
    return pytest.importorskip("trimesh").creation


# --------------------------------------------------------------------------
# Scene helpers
# --------------------------------------------------------------------------


def quad(y, x_range, z_range, *, facing_down=False):
    """Horizontal quad at height y, as a (vertices, faces) pair.

    Wound so its geometric normal is +y, or -y with ``facing_down``.
    """
    (x0, x1), (z0, z1) = x_range, z_range
    vertices = np.array([[x0, y, z0], [x0, y, z1], [x1, y, z1], [x1, y, z0]], dtype=np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    if facing_down:
        faces = faces[:, ::-1].copy()
    normal = np.cross(*(vertices[faces[0, 1:]] - vertices[faces[0, 0]]))
    assert np.sign(normal[1]) == (-1 if facing_down else 1)
    return vertices, faces


def floor_box(creation, half=10.0):
    """A box whose top face is the floor y = 0, |x|, |z| <= half."""
    box = creation.box(extents=(2 * half, 1.0, 2 * half))
    return np.asarray(box.vertices) - (0.0, 0.5, 0.0), np.asarray(box.faces, dtype=np.uint32)


def sphere(creation, center, radius, subdivisions=3):
    mesh = creation.icosphere(subdivisions=subdivisions, radius=radius)
    return np.asarray(mesh.vertices) + center, np.asarray(mesh.faces, dtype=np.uint32)


def scene_of(*meshes):
    return SimpleNamespace(meshes=list(meshes))


def camera(eye, target, up=(0.0, 1.0, 0.0), fov_y=40.0, resolution=(64, 48)):
    return ss.Camera.look_at(eye=eye, target=target, up=up, fov_y=fov_y, resolution=resolution)


def interval_overlap(lo, hi, half_width):
    """Length of [lo, hi] intersected with [-half_width, half_width]."""
    return np.clip(np.minimum(hi, half_width) - np.maximum(lo, -half_width), 0.0, None)


# The rectangular light 4 above the floor, facing down; frame n = -y, v = +z,
# u = n x v = -x. Non-square, so a swap of u and v changes the penumbrae.
LIGHT = ss.RectLight(center=(0.0, 4.0, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(1.5, 0.5))
# The plate at height 1 (planar depth 3 below the light), off-centre, spanning
# a in [-0.05, 0.45] along u and b in [-0.35, 0.15] along v, i.e. world
# x in [-0.45, 0.05], z in [-0.35, 0.15]. From the floor its back-projection
# is 4x larger (2.0 x 2.0), wider than the light: one edge per axis at most.
PLATE_HEIGHT, PLATE_A, PLATE_B = 1.0, (-0.05, 0.45), (-0.35, 0.15)


def exact_rect_visibility(points):
    """Closed-form visibility of floor points under the plate and LIGHT."""
    c, u, v, n = (np.array(x, dtype=float) for x in (LIGHT.center, (-1, 0, 0), (0, 0, 1), LIGHT.normal))
    rel = points - c
    pa, pb, depth = rel @ u, rel @ v, rel @ n
    plate_depth = c[1] - PLATE_HEIGHT
    scale = depth / (depth - plate_depth)
    sx, sy = LIGHT.size
    overlap_a = interval_overlap(pa + scale * (PLATE_A[0] - pa), pa + scale * (PLATE_A[1] - pa), sx / 2)
    overlap_b = interval_overlap(pb + scale * (PLATE_B[0] - pb), pb + scale * (PLATE_B[1] - pb), sy / 2)
    return 1.0 - overlap_a * overlap_b / (sx * sy)


def plate_mesh(*, facing_down=False):
    return quad(PLATE_HEIGHT, (-PLATE_A[1], -PLATE_A[0]), PLATE_B, facing_down=facing_down)


# --------------------------------------------------------------------------
# Rectangular light
# --------------------------------------------------------------------------


def test_plate_over_floor_matches_closed_form(eye, creation):
    # Wound facing down, so the reported normals show the flip to the camera.
    scene = scene_of(floor_box(creation), plate_mesh(facing_down=True))
    # Looking down at 60 degrees from the -z side (through the light, which
    # is not geometry) at the soft shadow, a in (-0.32, 0.85), b in
    # (-0.55, 0.28), and under the plate's edge into the umbra.
    elevation, target = np.radians(60.0), np.array([-0.25, 0.0, -0.1])
    cam = camera(
        tuple(target + 5.0 * np.array([0.0, np.sin(elevation), -np.cos(elevation)])), tuple(target), fov_y=16.0
    )
    image = eye.render_visibility(scene, LIGHT, cam, SAMPLES, seed=1)

    assert image.visibility.shape == (48, 64) and image.visibility.dtype == np.float32
    assert image.samples == SAMPLES and image.rays == SAMPLES * int(image.mask.sum())
    assert image.mask.all()  # the floor fills the view
    floor, plate = image.mesh_id == 0, image.mesh_id == 1
    assert np.count_nonzero(plate) > 100 and np.all(floor | plate)

    exact = exact_rect_visibility(image.position[floor])
    # The view spans lit floor, penumbra and umbra.
    assert np.count_nonzero(exact == 1.0) > 500 and np.count_nonzero((exact > 0) & (exact < 1)) > 500
    assert np.count_nonzero(exact == 0.0) > 30
    estimate = image.visibility[floor]
    error = np.abs(estimate - exact)
    assert error.max() < MAX_ERROR and error.mean() < MEAN_ERROR
    # Lit floor and umbra are exact (no acne on the floor either).
    assert np.all(estimate[exact == 1.0] == 1.0)
    assert np.all(estimate[exact == 0.0] == 0.0)
    # The plate's top sees the whole light: no self-shadowing by round-off.
    assert np.all(image.visibility[plate] == 1.0)
    # Only the top is seen: every plate normal faces up, toward the camera,
    # though the triangles' geometric normal is -y.
    np.testing.assert_array_equal(image.normal[plate], np.tile([0.0, 1.0, 0.0], (np.count_nonzero(plate), 1)))
    np.testing.assert_array_equal(image.normal[floor], np.tile([0.0, 1.0, 0.0], (np.count_nonzero(floor), 1)))
    np.testing.assert_allclose(image.position[plate][:, 1], PLATE_HEIGHT, atol=1e-6)


def test_sphere_shadows_itself(eye, creation):
    center = np.array([0.0, 1.5, 0.0])
    scene = scene_of(sphere(creation, center, 1.0))
    light = ss.RectLight(center=(0.0, 4.0, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(1.0, 1.0))
    # From the side, below the light: both hemispheres are in view.
    cam = camera((4.5, 3.0, 1.0), tuple(center), fov_y=35.0)
    image = eye.render_visibility(scene, light, cam, 64)
    hit = image.mask
    assert np.count_nonzero(hit) > 500 and np.all(image.mesh_id[hit] == 0)

    p, n = image.position[hit], image.normal[hit].astype(np.float64)
    # The normals are the outward face normals (the camera is outside).
    assert np.all(np.einsum("ij,ij->i", n, p - center) > 0.9)
    corners = np.array(light.corners(), dtype=np.float64)  # (4, 3)
    to_corner = corners[None, :, :] - p[:, None, :]
    cosine = np.einsum("ikj,ij->ik", to_corner, n) / np.linalg.norm(to_corner, axis=2)
    # Margins of 0.2 (11.5 degrees) exceed the ~8 degree turn between
    # neighbouring faces, so points next to an edge are decided too.
    umbra, lit = cosine.max(axis=1) < -0.2, cosine.min(axis=1) > 0.2
    assert np.count_nonzero(umbra) > 150 and np.count_nonzero(lit) > 80
    v = image.visibility[hit]
    assert np.all(v[umbra] == 0.0)
    assert np.all(v[lit] == 1.0)
    # And the terminator in between is soft.
    assert np.any((v > 0.0) & (v < 1.0))


def test_points_behind_the_light_plane_get_zero(eye):
    # The light 1 above the floor, facing down; a wall at z = -1 rises through its plane.
    light = ss.RectLight(center=(0.0, 1.0, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(1.0, 1.0))
    wall = (
        np.array([[-2.0, 0.0, -1.0], [2.0, 0.0, -1.0], [2.0, 3.0, -1.0], [-2.0, 3.0, -1.0]]),
        np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32),
    )
    scene = scene_of(quad(0.0, (-2.0, 2.0), (-1.0, 2.0)), wall)
    cam = camera((0.0, 1.5, 5.0), (0.0, 1.2, -1.0), fov_y=50.0)
    image = eye.render_visibility(scene, light, cam, 16)
    on_wall = image.mesh_id == 1
    height = image.position[..., 1]
    above, below = on_wall & (height > 1.0), on_wall & (height < 0.99)
    assert np.count_nonzero(above) > 200 and np.count_nonzero(below) > 100
    assert np.all(image.visibility[above] == 0.0)
    # Nothing stands between the lower wall or the floor and the light.
    assert np.all(image.visibility[below] == 1.0)
    assert np.all(image.visibility[image.mesh_id == 0] == 1.0)
    # No ray is traced for points behind the plane.
    assert image.rays == 16 * (int(image.mask.sum()) - int(np.count_nonzero(on_wall & (height > 1.0))))


# --------------------------------------------------------------------------
# Directional light
# --------------------------------------------------------------------------


def test_hard_sun_shadow_lands_where_geometry_says(eye, creation):
    direction = np.array([1.0, -1.0, 0.5]) / np.linalg.norm([1.0, -1.0, 0.5])
    sun = SimpleNamespace(direction=tuple(direction), up=(0.0, 0.0, 1.0), angular_size=(0.0, 0.0))
    scene = scene_of(floor_box(creation), quad(1.0, (-0.25, 0.25), (-0.25, 0.25)))
    # The shadow is the plate moved by (1, 0, 0.5): centred at x = 1, z = 0.5.
    cam = camera((1.0, 5.0, 0.5), (1.0, 0.0, 0.5), up=(0.0, 0.0, -1.0), fov_y=20.0)
    image = eye.render_visibility(scene, sun, cam, 64)
    assert image.samples == 1 and image.rays == int(image.mask.sum())
    floor = image.mesh_id == 0
    p = image.position[floor]
    # Trace each floor point back along -direction to the plate's height.
    q = p - (1.0 / -direction[1]) * direction
    inside = np.minimum(0.25 - np.abs(q[:, 0]), 0.25 - np.abs(q[:, 2]))
    shadowed, lit = inside > 1e-3, inside < -1e-3
    assert np.count_nonzero(shadowed) > 100 and np.count_nonzero(lit) > 500
    v = image.visibility[floor]
    assert np.all(v[shadowed] == 0.0) and np.all(v[lit] == 1.0)
    assert np.all(np.isin(v, (0.0, 1.0)))


def test_soft_sun_matches_closed_form(eye, creation):
    # Travelling straight down: n = -y, v = +z, u = n x v = -x.
    angles = (30.0, 12.0)
    sun = SimpleNamespace(direction=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), angular_size=angles)
    tan_u, tan_v = (np.tan(np.radians(a) / 2) for a in angles)
    height, a_range, b_range = 1.0, (0.0, 0.7), (-0.2, 0.3)
    # Both blocked (x, y) intervals (0.7 and 0.5 wide) are wider than the
    # light's (0.54 and 0.21): one edge per axis at most.
    plate = quad(height, (-a_range[1], -a_range[0]), b_range)
    scene = scene_of(floor_box(creation), plate)
    cam = camera((-0.35, 5.0, 0.05), (-0.35, 0.0, 0.05), up=(0.0, 0.0, -1.0), fov_y=18.0)
    image = eye.render_visibility(scene, sun, cam, SAMPLES, seed=2)
    floor = image.mesh_id == 0
    p = image.position[floor]
    pa, pb = -p[:, 0], p[:, 2]
    # The ray from P along -(n + x u + y v) meets the plate's plane at
    # (pa - height x, pb - height y) in (u, v).
    blocked_x = interval_overlap((pa - a_range[1]) / height, (pa - a_range[0]) / height, tan_u) / (2 * tan_u)
    blocked_y = interval_overlap((pb - b_range[1]) / height, (pb - b_range[0]) / height, tan_v) / (2 * tan_v)
    exact = 1.0 - blocked_x * blocked_y
    assert np.count_nonzero((exact > 0) & (exact < 1)) > 300 and np.count_nonzero(exact == 1.0) > 300
    error = np.abs(image.visibility[floor] - exact)
    assert error.max() < MAX_ERROR and error.mean() < MEAN_ERROR
    assert np.all(image.visibility[floor][exact == 1.0] == 1.0)
    assert np.all(image.visibility[image.mesh_id == 1] == 1.0)


# --------------------------------------------------------------------------
# Geometry of the first hits
# --------------------------------------------------------------------------


def test_mask_depth_position_and_mesh_id(eye, creation):
    empty = (np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32))
    ball_center, ball_radius = np.array([0.8, 0.5, -0.5]), 0.5
    # The empty mesh keeps its index: the floor is 1 and the ball 2.
    scene = scene_of(empty, quad(0.0, (-2.0, 2.0), (-2.0, 2.0)), sphere(creation, ball_center, ball_radius))
    cam = camera((0.0, 2.5, 4.0), (0.0, 0.0, 0.0), fov_y=50.0)
    image = eye.render_visibility(scene, LIGHT, cam, 4)

    eye_pos, forward = np.array(cam.eye), np.array(cam.forward)
    d = cam.ray_directions()
    with np.errstate(divide="ignore"):
        t_floor = np.where(d[..., 1] < 0, -eye_pos[1] / d[..., 1], np.inf)
    q = eye_pos + np.where(np.isfinite(t_floor), t_floor, 0.0)[..., None] * d
    extent = np.maximum(np.abs(q[..., 0]), np.abs(q[..., 2]))
    # Distance of each ray to the ball's centre; the icosphere lies between
    # its inscribed ball (radius > 0.98 r at 3 subdivisions) and the sphere.
    along = (ball_center - eye_pos) @ d.reshape(-1, 3).T
    miss_distance = np.linalg.norm(eye_pos + along.reshape(48, 64)[..., None] * d - ball_center, axis=-1)
    misses_ball, hits_ball = miss_distance > ball_radius * 1.001, miss_distance < ball_radius * 0.97
    on_floor = np.isfinite(t_floor) & (extent < 1.99) & misses_ball
    background = (~np.isfinite(t_floor) | (extent > 2.01)) & misses_ball
    assert np.count_nonzero(on_floor) > 500 and np.count_nonzero(background) > 200
    assert np.count_nonzero(hits_ball) > 50

    assert np.all(image.mask[on_floor]) and np.all(image.mesh_id[on_floor] == 1)
    depth = t_floor[on_floor] * (d[on_floor] @ forward)
    np.testing.assert_allclose(image.depth[on_floor], depth, rtol=2e-6)
    np.testing.assert_allclose(image.position[on_floor], q[on_floor], atol=1e-5 * t_floor[on_floor].max())
    assert np.all(image.normal[on_floor] == np.array([0.0, 1.0, 0.0], dtype=np.float32))
    assert np.all(image.mesh_id[hits_ball] == 2)
    assert np.all(image.depth[hits_ball] < image.depth.max(where=on_floor, initial=0.0))

    assert not np.any(image.mask[background])
    assert np.all(image.mesh_id[background] == -1)
    assert np.all(np.isinf(image.depth[background])) and np.all(np.isnan(image.position[background]))
    assert np.all(image.normal[background] == 0.0) and np.all(image.visibility[background] == 1.0)
    # Everywhere: depth is the position's distance along the optical axis.
    hit = image.mask
    np.testing.assert_allclose(image.depth[hit], (image.position[hit] - eye_pos) @ forward, rtol=1e-6)
    assert image.mesh_id.dtype == np.int32 and image.depth.dtype == np.float32
    assert image.normal.dtype == np.float32 and image.position.dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(image.normal[hit], axis=-1), 1.0, atol=1e-6)


def test_many_meshes_keep_their_indices(eye, creation):
    """Twelve balls in a row: more than ten, so name order ('mesh_10' <
    'mesh_2') would differ from list order."""
    centers = [np.array([x, 0.0, 0.0]) for x in np.linspace(-2.2, 2.2, 12)]
    scene = scene_of(*(sphere(creation, c, 0.15, subdivisions=1) for c in centers))
    cam = camera((0.0, 0.0, 6.0), (0.0, 0.0, 0.0), fov_y=30.0, resolution=(96, 32))
    image = eye.render_visibility(scene, LIGHT, cam, 1)
    k, world_from_camera = cam.to_opencv()
    camera_from_world = np.linalg.inv(world_from_camera)
    for index, c in enumerate(centers):
        uvw = k @ (camera_from_world @ np.append(c, 1.0))[:3]
        i, j = np.rint(uvw[:2] / uvw[2]).astype(int)
        assert image.mesh_id[j, i] == index
    assert set(np.unique(image.mesh_id)) == {-1, *range(12)}


# --------------------------------------------------------------------------
# Determinism, batching, variants, inputs
# --------------------------------------------------------------------------


def small_render(module, seed=0, resolution=(32, 24), samples=64):
    scene = scene_of(quad(0.0, (-3.0, 3.0), (-3.0, 3.0)), plate_mesh())
    cam = camera((1.0, 5.0, 3.0), (0.0, 0.0, 0.0), fov_y=30.0, resolution=resolution)
    return module.render_visibility(scene, LIGHT, cam, samples, seed=seed)


def test_seed_determinism_and_batching(eye, monkeypatch):
    first = small_render(eye, seed=7)
    np.testing.assert_array_equal(first.visibility, small_render(eye, seed=7).visibility)
    assert np.any(first.visibility != small_render(eye, seed=8).visibility)
    # Tiny batches (15 pixels of 64 rays; 1000 camera rays) change nothing.
    monkeypatch.setattr(eye._rays, "MAX_RAYS_PER_BATCH", 1000)
    again = small_render(eye, seed=7)
    for field in ("visibility", "mask", "depth", "normal", "mesh_id"):
        np.testing.assert_array_equal(getattr(again, field), getattr(first, field))
    np.testing.assert_array_equal(again.position, first.position)
    assert again.rays == first.rays
    # Two seeds agree up to noise on the same pixels.
    other = metrics.compare_images(small_render(eye, seed=8), first)
    assert other.matched_fraction == 1.0 and 0.0 < other.mean_abs < 0.05


def test_scalar_variant_agrees(eye):
    """The scalar fallback (forced in a fresh process) gives the same image."""
    script = textwrap.dedent(
        """
        import sys, numpy as np
        sys.path.insert(0, sys.argv[1])
        import test_reference_eye as t
        from softshadow import reference
        image = t.small_render(reference, seed=3, resolution=(12, 9), samples=16)
        np.savez(sys.argv[2], variant=reference.variant(), **{
            f: getattr(image, f) for f in ("visibility", "mask", "depth", "position", "mesh_id", "normal")})
        """
    )
    env = dict(os.environ, SOFTSHADOW_MITSUBA_VARIANT="scalar_rgb")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(ss.__file__).parent.parent)] + sys.path)
    out = Path(os.environ.get("TMPDIR", "/tmp")) / f"softshadow-eye-scalar-{os.getpid()}.npz"
    here = str(Path(__file__).parent)
    result = subprocess.run(
        [sys.executable, "-c", script, here, str(out)], env=env, capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr
    try:
        with np.load(out) as scalar:
            scalar = dict(scalar)
    finally:
        out.unlink(missing_ok=True)
    assert str(scalar["variant"]) == "scalar_rgb"
    vector = small_render(eye, seed=3, resolution=(12, 9), samples=16)
    np.testing.assert_array_equal(scalar["mask"], vector.mask)
    np.testing.assert_array_equal(scalar["mesh_id"], vector.mesh_id)
    np.testing.assert_allclose(scalar["depth"], vector.depth, rtol=1e-6)
    np.testing.assert_allclose(scalar["normal"], vector.normal, atol=1e-6)
    # Same seed, same rays: only rays grazing an edge may differ.
    np.testing.assert_allclose(scalar["visibility"], vector.visibility, atol=2 / 16)


def test_empty_scene_and_repr(eye):
    cam = camera((0.0, 1.0, 3.0), (0.0, 0.0, 0.0), resolution=(8, 6))
    image = eye.render_visibility(scene_of(), LIGHT, cam, 4)
    assert not image.mask.any() and image.rays == 0
    np.testing.assert_array_equal(image.visibility, 1.0)
    assert np.all(image.mesh_id == -1) and np.all(np.isinf(image.depth))
    text = repr(image)
    assert text.startswith("ReferenceImage(8x6") and len(text) < 200
    with pytest.raises(AttributeError):
        image.samples = 3  # type: ignore[misc]


@pytest.mark.parametrize(
    ("scene", "light", "samples", "error", "match"),
    [
        (SimpleNamespace(), LIGHT, 4, TypeError, "scene"),
        (scene_of(), LIGHT, 0, ValueError, "samples"),
        (scene_of(), SimpleNamespace(center=(0, 0, 0)), 4, TypeError, "light"),
        (scene_of(), SimpleNamespace(direction=(0, -1, 0), up=(0, 0, 1)), 4, TypeError, "angular_size"),
        (
            scene_of(),
            SimpleNamespace(direction=(0, -1, 0), up=(0, 0, 1), angular_size=(-1, 0)),
            4,
            ValueError,
            "angular_size",
        ),
        (
            scene_of(),
            SimpleNamespace(direction=(0, -1, 0), up=(0, 1, 0), angular_size=(1, 1)),
            4,
            ValueError,
            "light.up",
        ),
        (scene_of((np.zeros((3, 3)), np.array([[0, 1, 5]]))), LIGHT, 4, ValueError, r"scene.meshes\[0\]"),
    ],
)
def test_validation(scene, light, samples, error, match):
    cam = camera((0.0, 1.0, 3.0), (0.0, 0.0, 0.0), resolution=(8, 6))
    with pytest.raises(error, match=match):
        reference.render_visibility(scene, light, cam, samples)


# --------------------------------------------------------------------------
# compare_images (NumPy only)
# --------------------------------------------------------------------------


def synthetic_image(height=6, width=8):
    """A floor at depth 2 + row/10 in the lower rows, background above."""
    mask = np.zeros((height, width), dtype=bool)
    mask[2:] = True
    depth = np.where(mask, 2.0 + np.arange(height)[:, None] / 10.0, np.inf).astype(np.float32)
    position = np.full((height, width, 3), np.nan)
    rows, cols = np.nonzero(mask)
    position[rows, cols] = np.stack([cols * 0.1, np.zeros_like(cols, dtype=float), -depth[rows, cols]], axis=1)
    visibility = np.ones((height, width), dtype=np.float32)
    visibility[mask] = np.linspace(0.0, 1.0, mask.sum())
    mesh_id = np.where(mask, 0, -1).astype(np.int32)
    return SimpleNamespace(visibility=visibility, mask=mask, depth=depth, position=position, mesh_id=mesh_id)


def test_compare_identical_images():
    image = synthetic_image()
    result = metrics.compare_images(image, synthetic_image())
    assert result.matched == 32 and result.matched_fraction == 1.0 and result.mismatched == 0
    assert result.mean_abs == result.rmse == result.max_abs == result.p99_abs == 0.0
    assert result.shadow_error == result.acne == result.leak == 0.0 and result.shadowed == 31
    np.testing.assert_array_equal(result.mask, image.mask)
    assert repr(result).startswith("ImageComparison(matched=32") and len(repr(result)) < 250


def test_compare_errors_and_matching():
    reference_image, image = synthetic_image(), synthetic_image()
    image.visibility = image.visibility.copy()
    image.visibility[4:] = np.clip(image.visibility[4:] + 0.25, None, 2.0)  # 16 pixels off by 0.25
    # Pixel (2, 0) (depth 2.2) moves by 2e-4 < 1e-4 * 2.2: still matched;
    # pixel (2, 1) by 3e-4 > 2.2e-4: not matched.
    image.position = image.position.copy()
    image.position[2, 0, 0] += 2e-4
    image.position[2, 1, 0] += 3e-4
    # Another mesh at (3, 0), and a hit only in the image at (0, 0).
    image.mesh_id = image.mesh_id.copy()
    image.mesh_id[3, 0] = 1
    image.mask = image.mask.copy()
    image.mask[0, 0] = True
    image.mesh_id[0, 0] = 0
    result = metrics.compare_images(image, reference_image)
    expected = reference_image.mask.copy()
    expected[2, 1] = expected[3, 0] = False
    np.testing.assert_array_equal(result.mask, expected)
    assert result.matched == 30 and result.mismatched == 3
    assert result.matched_fraction == pytest.approx(30 / 33)
    errors = np.where(np.arange(6)[:, None] >= 4, 0.25, 0.0) * np.ones((6, 8))
    errors = errors[expected]
    assert result.mean_abs == pytest.approx(errors.mean(), abs=1e-7)
    assert result.rmse == pytest.approx(np.sqrt(np.mean(errors**2)), abs=1e-7)
    assert result.max_abs == pytest.approx(0.25, abs=1e-7)
    assert result.p99_abs == pytest.approx(0.25, abs=1e-7)
    # A looser tolerance matches the moved pixel too.
    assert metrics.compare_images(image, reference_image, position_tol=1e-3).matched == 31


def test_grain_is_the_per_pixel_noise_the_reference_has_not():
    # A smooth ramp of penumbra over a 12 x 16 floor; the image adds +-0.02
    # in a checkerboard (what per-pixel sample patterns draw) on the rows
    # whose 3x3 blocks are all floor.
    reference_image, image = synthetic_image(12, 16), synthetic_image(12, 16)
    assert metrics.compare_images(image, reference_image).grain == pytest.approx(0.0, abs=1e-12)
    image.visibility = image.visibility.copy()
    checker = np.where((np.arange(12)[:, None] + np.arange(16)) % 2 == 0, 0.02, -0.02)
    image.visibility += checker.astype(np.float32) * image.mask
    g = metrics.compare_images(image, reference_image).grain
    # |c - box(c)| of a +-0.02 checkerboard inside: 0.02 - 0.02 / 9.
    assert g == pytest.approx(0.02 * 8 / 9, rel=1e-3)
    # A uniform offset is error, not grain.
    image.visibility = reference_image.visibility + 0.03 * reference_image.mask
    assert metrics.compare_images(image, reference_image).grain == pytest.approx(0.0, abs=1e-6)


def test_compare_images_reports_the_shadowed_pixels_acne_and_leaks():
    # The reference: 32 floor pixels with V_ref from 0 to 1; 0 is umbra, the
    # last one (1.0) fully lit.
    reference_image, image = synthetic_image(), synthetic_image()
    v_ref = reference_image.visibility[reference_image.mask].astype(np.float64)
    image.visibility = image.visibility.copy()
    # Lighten the umbra pixel by 0.2 (a leak), darken the lit one by 0.1
    # (acne) and one penumbra pixel by 0.04 (neither).
    rows, cols = np.nonzero(reference_image.mask)
    image.visibility[rows[0], cols[0]] += 0.2
    image.visibility[rows[-1], cols[-1]] -= 0.1
    image.visibility[rows[10], cols[10]] -= 0.04
    result = metrics.compare_images(image, reference_image)
    shadowed = (1.0 - v_ref) > 1e-3
    assert result.shadowed == int(shadowed.sum()) == 31
    assert result.shadow_error == pytest.approx((0.2 + 0.04) / 31, abs=1e-7)
    # The mean over every matched pixel is lower: the lit one counts too.
    assert result.mean_abs == pytest.approx(0.34 / 32, abs=1e-7)
    assert result.acne == pytest.approx(1 / 32) and result.leak == pytest.approx(1 / 32)
    assert "shadow_error=" in repr(result) and "acne=3.12%" in repr(result)
    # A stricter threshold leaves the shadow error over fewer pixels.
    assert metrics.compare_images(image, reference_image, threshold=0.5).shadowed == int(((1 - v_ref) > 0.5).sum())
    with pytest.raises(ValueError, match="threshold"):
        metrics.compare_images(image, reference_image, threshold=1.0)


def test_compare_shape_mismatch_names_the_argument():
    small = synthetic_image(4, 8)
    with pytest.raises(ValueError, match="reference.visibility"):
        metrics.compare_images(synthetic_image(), small)
    bad = synthetic_image()
    bad.position = bad.position[..., :2]
    with pytest.raises(ValueError, match="image.position"):
        metrics.compare_images(bad, synthetic_image())
    bad = synthetic_image()
    bad.mesh_id = bad.mesh_id[:, :4]
    with pytest.raises(ValueError, match="reference.mesh_id"):
        metrics.compare_images(synthetic_image(), bad)
    with pytest.raises(TypeError, match="reference has no attribute 'mask'"):
        metrics.compare_images(synthetic_image(), SimpleNamespace(visibility=np.ones((6, 8))))
    with pytest.raises(ValueError, match="position_tol"):
        metrics.compare_images(synthetic_image(), synthetic_image(), position_tol=-1.0)
