"""The Mitsuba references (softshadow.reference) under disk and sphere lights.

* ``render_direct``: Mitsuba's ``direct`` integrator on an unoccluded floor
  equals ``albedo / pi * light.irradiance_at`` (softshadow's closed form),
  which checks the ``disk`` emitter's orientation, side and size and the
  ``sphere`` emitter's, horizon clipping included.
* ``render_visibility``: agrees with ``softshadow.render(method=Exact)`` on a
  plate over a floor, and with closed forms where the occluder's shadow is
  wholly inside the light: a square plate parallel to a disk hides the
  homothetic image of itself in the disk's plane (an area fraction), and
  hides the square's solid angle (Van Oosterom and Strackee) of a sphere's
  cone.
* The conventions at the edges: 0 at or behind a disk's plane and inside a
  sphere, no ray traced there.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import reference

ALBEDO = 0.8


@pytest.fixture(scope="module")
def mitsuba_reference():
    """The reference package, skipping when Mitsuba is missing."""
    pytest.importorskip("mitsuba")
    pytest.importorskip("drjit")
    return reference


def quad(y, x_range, z_range):
    """Horizontal quad at height y (two triangles, normal +y)."""
    (x0, x1), (z0, z1) = x_range, z_range
    vertices = np.array([[x0, y, z0], [x0, y, z1], [x1, y, z1], [x1, y, z0]], dtype=np.float64)
    return vertices, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)


def camera(eye, target, fov_y, resolution):
    return ss.Camera.look_at(eye=eye, target=target, up=(0.0, 1.0, 0.0), fov_y=fov_y, resolution=resolution)


# --------------------------------------------------------------------------
# render_direct: Mitsuba's emitters against the closed-form irradiance
# --------------------------------------------------------------------------

# The floor y = 0, its far edge at x = 0.4; the lights stand beyond it or
# high above it, never touching it.
FLOOR_X, FLOOR_Z = (-4.0, 0.4), (-3.0, 3.0)
DIRECT_CAMERA = dict(eye=(-5.0, 3.0, 0.5), target=(-1.0, 0.0, 0.0), fov_y=60.0, resolution=(48, 36))
DIRECT_LIGHTS = {
    # Tilted (facing -x, down and toward +z) and off-centre, beyond the floor's
    # edge (x >= 0.61) and dipping below y = 0 (to y = -0.33): every floor
    # point sees it cut by its horizon, and the floor beyond the line where
    # its plane crosses y = 0 is behind it.
    "disk": ss.DiskLight((1.0, 0.25, 0.0), (-1.0, -0.3, 0.8), 0.6, radiance=(1.0, 2.0, 3.0)),
    # Wholly above the floor's plane (centre 1.2 above it, radius 1.0), just
    # past the floor's z = -3 edge, where no camera ray to the floor meets it.
    "sphere_above": ss.SphereLight((-1.0, 1.2, -3.5), 1.0, radiance=(3.0, 2.0, 1.0)),
    # Beyond the floor's edge (x >= 0.6) and partly below its plane (down to
    # y = -0.5): every floor point sees its cap cut by the horizon.
    "sphere_cut": ss.SphereLight((1.6, 0.5, 0.0), 1.0, radiance=(2.0, 2.0, 1.0)),
}
# Mitsuba's noise, measured at these settings (1024 samples per pixel,
# 48x36, 965 floor pixels, seeds 0 and 1): mean|seed 0 - seed 1| / mean is
# 0.0013 (disk), 0.0010 (sphere above) and 0.0020 (sphere cut); each seed's
# error against the closed form, the same measure, 0.0008 to 0.0010,
# 0.0007 and 0.0013 to 0.0015; its bias (mean signed error / mean, per
# channel) at most 1.7e-4. The bounds are twice the largest noise and six
# times the largest bias.
DIRECT_SAMPLES = 1024
DIRECT_MEAN_BOUND = 0.004
DIRECT_BIAS_BOUND = 0.001


def _floor_points(cam):
    """Camera rays' hits on the floor y = 0, and which lie on the floor quad
    (0.02 inside its edges, clear of the silhouette pixels)."""
    eye = np.asarray(cam.eye, dtype=np.float64)
    d = cam.ray_directions().reshape(-1, 3)
    t = np.where(d[:, 1] < 0.0, -eye[1] / np.minimum(d[:, 1], -1e-12), np.inf)
    points = eye + np.where(np.isfinite(t), t, 0.0)[:, None] * d
    margin = 0.02
    inside = (
        np.isfinite(t)
        & (points[:, 0] > FLOOR_X[0] + margin)
        & (points[:, 0] < FLOOR_X[1] - margin)
        & (points[:, 2] > FLOOR_Z[0] + margin)
        & (points[:, 2] < FLOOR_Z[1] - margin)
    )
    return points, inside, t


def _rays_meet_sphere(cam, light, t_floor):
    """Which camera rays meet the sphere before the floor."""
    eye = np.asarray(cam.eye, dtype=np.float64)
    d = cam.ray_directions().reshape(-1, 3)
    oc = eye - np.asarray(light.center)
    b = d @ oc
    disc = b * b - (oc @ oc - light.radius**2)
    near = -b - np.sqrt(np.maximum(disc, 0.0))
    return (disc > 0.0) & (near > 0.0) & (near < t_floor)


@pytest.mark.parametrize("name", sorted(DIRECT_LIGHTS))
def test_direct_matches_the_closed_form_irradiance(mitsuba_reference, name):
    light = DIRECT_LIGHTS[name]
    cam = camera(**DIRECT_CAMERA)
    scene = ss.Scene(meshes=[quad(0.0, FLOOR_X, FLOOR_Z)])
    points, inside, t_floor = _floor_points(cam)
    assert inside.sum() > 800
    normals = np.tile([0.0, 1.0, 0.0], (int(inside.sum()), 1))
    want = ALBEDO / np.pi * light.irradiance_at(points[inside], normals)

    # The geometry is what the names say; the lights stay off the floor and
    # out of the camera rays (Mitsuba's emitter shapes are geometry).
    c, r = np.asarray(light.center), light.radius
    if isinstance(light, ss.DiskLight):
        n = np.asarray(light.n)
        lowest = c[1] - r * np.sqrt(1.0 - n[1] ** 2)
        nearest_x = c[0] - r * np.sqrt(1.0 - n[0] ** 2)
        assert lowest < 0.0 and nearest_x > FLOOR_X[1]  # cut by the horizon, off the floor
        # The camera (x = -5) sees the floor (x <= 0.4) before any ray gets to the disk.
        assert cam.eye[0] < FLOOR_X[1]
        behind = (points[inside] - c) @ n <= 0.0
        assert behind.sum() > 20 and np.all(want[behind] == 0.0) and np.all(want[~behind] > 0.0)
    elif name == "sphere_cut":
        assert c[1] < r and c[0] - r > FLOOR_X[1]
    else:
        assert c[1] > r
    if isinstance(light, ss.SphereLight):
        assert not np.any(_rays_meet_sphere(cam, light, t_floor)[inside])

    image = mitsuba_reference.render_direct(scene, light, cam, albedo=ALBEDO, samples=DIRECT_SAMPLES, seed=0)
    got = image.reshape(-1, 3)[inside].astype(np.float64)
    # Behind the disk: exactly nothing, as the closed form.
    np.testing.assert_array_equal(got[want == 0.0], 0.0)
    error = np.abs(got - want).mean() / want.mean()
    bias = (got - want).mean(axis=0) / want.mean(axis=0)
    assert error < DIRECT_MEAN_BOUND, (error, bias)
    assert np.all(np.abs(bias) < DIRECT_BIAS_BOUND), bias


# --------------------------------------------------------------------------
# render_visibility against softshadow.render (exact)
# --------------------------------------------------------------------------

PLATE_SCENE = [quad(0.0, (-3.0, 3.0), (-3.0, 3.0)), quad(1.0, (-0.5, 0.3), (-0.4, 0.4))]
PLATE_CAMERA = dict(eye=(0.0, 4.0, 3.5), target=(0.0, 0.0, -0.3), fov_y=45.0, resolution=(64, 48))
PLATE_LIGHTS = {
    "disk": ss.DiskLight((0.3, 2.5, -0.2), (0.2, -1.0, 0.1), 0.6),
    "sphere": ss.SphereLight((0.3, 2.8, -0.2), 0.5),
}


@pytest.mark.parametrize("name", sorted(PLATE_LIGHTS))
def test_visibility_agrees_with_exact(mitsuba_reference, name):
    """Measured: mean |dV| over the reference's shadowed pixels 0.0020
    (disk, 393 pixels) and 0.0026 (sphere, 319 pixels), the reference's own
    seed-to-seed difference there 0.0022 and 0.0025; the largest 0.010 and
    0.013."""
    light = PLATE_LIGHTS[name]
    scene = ss.Scene(meshes=PLATE_SCENE)
    cam = camera(**PLATE_CAMERA)
    ref = mitsuba_reference.render_visibility(scene, light, cam, 1024, seed=0)
    ours = ss.render(scene, light, cam, method=ss.Exact(samples=1024))
    np.testing.assert_array_equal(ref.mask, ours.mask)
    same = ref.mask & (ref.mesh_id == ours.mesh_id)
    assert same.sum() > 0.99 * ref.mask.sum()
    shadowed = same & (ref.visibility < 1.0)
    assert shadowed.sum() > 200 and np.count_nonzero(same & (ref.visibility == 0.0)) > 20
    difference = np.abs(ref.visibility - ours.visibility)
    assert difference[shadowed].mean() <= 0.01
    assert difference[shadowed].max() < 0.05
    # The plate's top and the floor far from the plate see the whole light.
    assert np.all(ref.visibility[same & (ref.mesh_id == 1)] == 1.0)


# --------------------------------------------------------------------------
# render_visibility against closed forms
# --------------------------------------------------------------------------

# A square plate (centre (PLATE_X, 2, 0), half-side ``half``) parallel to the
# floor and to the disk light at height 3 facing down: from a floor point p
# (height 0) the plate hides its image by the homothety of centre p and ratio
# 3 / 2 in the disk's plane, and its solid angle of a sphere's cone.
PLATE_HEIGHT, PLATE_X = 2.0, 0.2
ANALYTIC_CAMERA = dict(eye=(0.3, 3.5, 4.0), target=(0.0, 0.0, 0.5), fov_y=70.0, resolution=(48, 36))
ANALYTIC_SAMPLES = 1024
# (light, the plate's half-side)
ANALYTIC_LIGHTS = {
    "disk": (ss.DiskLight((0.0, 3.0, 0.0), (0.0, -1.0, 0.0), 1.5), 0.25),
    # Off the plate's axis, its bottom (2.2) above the plate, so the plate is between.
    "sphere": (ss.SphereLight((1.5, 3.3, 0.0), 1.1), 0.15),
}


def _plate(half):
    return quad(PLATE_HEIGHT, (PLATE_X - half, PLATE_X + half), (-half, half))


def _plate_corners(half):
    x, y = PLATE_X, PLATE_HEIGHT
    return np.array([[x - half, y, -half], [x + half, y, -half], [x + half, y, half], [x - half, y, half]])


def _disk_closed_form(light, half, points):
    """(visibility, known, inside): the closed form where the plate's image
    lies wholly inside the disk (``inside``) or wholly outside it."""
    c, r = np.asarray(light.center), light.radius
    ratio = (c[1] - points[:, 1]) / (PLATE_HEIGHT - points[:, 1])  # homothety ratio, > 1
    image_half = half * ratio
    plate_centre = np.array([PLATE_X, 0.0])
    centre = points[:, [0, 2]] + ratio[:, None] * (plate_centre - points[:, [0, 2]])
    offset = np.linalg.norm(centre - c[[0, 2]], axis=1)
    inside = offset + image_half * np.sqrt(2.0) <= r
    outside = offset - image_half * np.sqrt(2.0) >= r
    visibility = np.where(inside, 1.0 - (2.0 * image_half) ** 2 / (np.pi * r * r), 1.0)
    return visibility, inside | outside, inside


def _triangle_solid_angle(p, a, b, c):
    """Solid angle of triangle abc seen from points p (Van Oosterom and Strackee)."""
    ra, rb, rc = a - p, b - p, c - p
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (ra, rb, rc))
    triple = np.abs(np.einsum("ij,ij->i", ra, np.cross(rb, rc)))
    dot = lambda x, y: np.einsum("ij,ij->i", x, y)  # noqa: E731
    denominator = la * lb * lc + dot(ra, rb) * lc + dot(ra, rc) * lb + dot(rb, rc) * la
    return 2.0 * np.arctan2(triple, denominator)


def _square_solid_angle(points, corners):
    return sum(
        _triangle_solid_angle(points, *(np.broadcast_to(corners[k], points.shape) for k in triangle))
        for triangle in ((0, 1, 2), (0, 2, 3))
    )


def _sphere_closed_form(light, half, points):
    """(visibility, known, inside): where the plate lies wholly inside the
    sphere's cone (``inside``), one minus its solid angle over the cone's;
    where its bounding sphere lies wholly outside the cone, 1."""
    c, r = np.asarray(light.center), light.radius
    axis = c - points
    distance = np.linalg.norm(axis, axis=1)
    axis /= distance[:, None]
    alpha = np.arcsin(r / distance)
    corners = _plate_corners(half)
    to_corner = corners[None, :, :] - points[:, None, :]
    to_corner /= np.linalg.norm(to_corner, axis=2, keepdims=True)
    corner_angle = np.arccos(np.clip(np.einsum("ikj,ij->ik", to_corner, axis), -1.0, 1.0))
    inside = corner_angle.max(axis=1) < alpha  # the square is convex: so is its cone
    to_plate = np.array([PLATE_X, PLATE_HEIGHT, 0.0]) - points
    plate_distance = np.linalg.norm(to_plate, axis=1)
    plate_angle = np.arccos(np.clip(np.einsum("ij,ij->i", to_plate / plate_distance[:, None], axis), -1.0, 1.0))
    plate_radius = np.arcsin(np.minimum(half * np.sqrt(2.0) / plate_distance, 1.0))
    outside = plate_angle - plate_radius > alpha
    cap = 2.0 * np.pi * (1.0 - np.cos(alpha))
    visibility = np.where(inside, 1.0 - _square_solid_angle(points, corners) / cap, 1.0)
    return visibility, inside | outside, inside


def test_square_solid_angle_on_its_axis():
    # A square of half-side a at distance h on its axis: 4 asin(a^2 / (a^2 + h^2)).
    a, h = 0.4, 1.3
    p = np.array([[PLATE_X, PLATE_HEIGHT - h, 0.0]])
    omega = _square_solid_angle(p, _plate_corners(a))
    np.testing.assert_allclose(omega, 4.0 * np.arcsin(a * a / (a * a + h * h)), rtol=1e-12)


@pytest.mark.parametrize("name", sorted(ANALYTIC_LIGHTS))
def test_visibility_matches_closed_form(mitsuba_reference, name):
    """Measured (1024 samples, seeds 2 and 3): on the floor pixels where the
    plate's shadow lies wholly in the light, mean |error| 0.0019 and 0.0018,
    largest 0.0073, mean error (bias) at most 4e-4 (disk, 206 pixels, V =
    0.920); 0.0017 and 0.0018, 0.0069, 4e-5 (sphere, 158 pixels, V in 0.929
    to 0.983). A disk sampled with r linear in u (not area-uniform) gives
    mean |error| 0.044; a sphere sampled with 1 - cos(theta) along u^1.3
    (not solid-angle-uniform) 0.0066 and a bias of -0.004."""
    light, half = ANALYTIC_LIGHTS[name]
    scene = ss.Scene(meshes=[quad(0.0, (-4.0, 4.0), (-4.0, 4.0)), _plate(half)])
    image = mitsuba_reference.render_visibility(scene, light, camera(**ANALYTIC_CAMERA), ANALYTIC_SAMPLES, seed=2)
    floor = image.mesh_id == 0
    closed_form = _disk_closed_form if name == "disk" else _sphere_closed_form
    want, known, inside = closed_form(light, half, image.position[floor])
    got = image.visibility[floor]
    assert inside.sum() > 100 and (known & ~inside).sum() > 100
    # Wholly outside: exact.
    np.testing.assert_array_equal(got[known & ~inside], 1.0)
    error = got[inside] - want[inside]
    assert np.abs(error).mean() < 0.004 and np.abs(error).max() < 0.03, (np.abs(error).mean(), np.abs(error).max())
    assert abs(error.mean()) < 0.001, error.mean()
    assert np.all(image.visibility[image.mesh_id == 1] == 1.0)


# --------------------------------------------------------------------------
# Conventions at the edges
# --------------------------------------------------------------------------


def test_points_behind_a_disk_and_inside_a_sphere_get_zero(mitsuba_reference):
    # A wall at z = -1 rising through the plane of a disk 1 above the floor,
    # facing down; nothing else occludes.
    wall = (
        np.array([[-2.0, 0.0, -1.0], [2.0, 0.0, -1.0], [2.0, 3.0, -1.0], [-2.0, 3.0, -1.0]]),
        np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32),
    )
    scene = ss.Scene(meshes=[quad(0.0, (-2.0, 2.0), (-1.0, 2.0)), wall])
    cam = camera((0.0, 1.5, 5.0), (0.0, 1.2, -1.0), 50.0, (32, 24))
    disk = ss.DiskLight((0.0, 1.0, 0.0), (0.0, -1.0, 0.0), 0.5)
    image = mitsuba_reference.render_visibility(scene, disk, cam, 16)
    on_wall, height = image.mesh_id == 1, image.position[..., 1]
    above, below = on_wall & (height >= 1.0), on_wall & (height < 0.99)
    assert above.sum() > 50 and below.sum() > 30
    assert np.all(image.visibility[above] == 0.0)
    assert np.all(image.visibility[below] == 1.0) and np.all(image.visibility[image.mesh_id == 0] == 1.0)
    assert image.rays == 16 * int((image.mask & ~above).sum())

    # A sphere crossing the floor: 0 inside. Outside, a floor point's rays to
    # the cap, partly below its horizon, leave through the floor's near or far
    # side and are all clear (the wall points see the part below the floor
    # through it, and the floor blocks those rays).
    sphere = ss.SphereLight((0.2, 0.2, 0.8), 0.8)
    image = mitsuba_reference.render_visibility(scene, sphere, cam, 16)
    distance = np.linalg.norm(image.position - np.asarray(sphere.center), axis=-1)
    inside = image.mask & (distance <= sphere.radius)
    assert inside.sum() > 20 and np.all(image.mesh_id[inside] == 0)
    assert np.all(image.visibility[inside] == 0.0)
    np.testing.assert_array_equal(image.visibility[(image.mesh_id == 0) & ~inside], 1.0)
    assert np.any(image.visibility[image.mesh_id == 1] < 1.0)
    assert image.rays == 16 * int((image.mask & ~inside).sum())


def test_disk_and_sphere_samples_are_uniform_and_stratified():
    """The samplers alone (NumPy): a disk's samples cover it uniformly in
    area (its strata are the rectangle's, carried by an area-preserving
    map), a sphere's directions its cone uniformly in solid angle, each
    point's K of them one per stratum of (1 - cos theta, phi)."""
    from softshadow.reference import eye

    rng = np.random.default_rng(5)
    disk = eye._sampler(ss.DiskLight((1.0, 2.0, 3.0), (0.3, -1.0, 0.2), 0.7), 64)
    s, t = (x.astype(np.float64).reshape(200, 64) for x in disk.offsets(200, rng))
    radius2 = (s * s + t * t) / 0.49
    assert radius2.max() <= 1.0 + 1e-6
    # Uniform in area: r^2 / R^2 is uniform on [0, 1]; each of 16 strata of
    # r^2 x angle holds 1/16 of the samples up to the stratified noise.
    angle = np.arctan2(t, s)
    cells = np.minimum((radius2 * 4).astype(int), 3) * 4 + ((angle + np.pi) / (np.pi / 2)).astype(int) % 4
    counts = np.bincount(cells.ravel(), minlength=16)
    np.testing.assert_allclose(counts / counts.sum(), 1 / 16, atol=0.004)
    np.testing.assert_allclose(np.asarray(disk.u) @ disk.n, 0.0, atol=1e-12)
    np.testing.assert_allclose(np.cross(disk.n, disk.v), disk.u, atol=1e-12)

    sphere = eye._sampler(ss.SphereLight((0.0, 3.0, 0.0), 0.8), 64)
    points = np.array([[0.0, 0.0, 0.0], [2.0, 1.0, -1.0], [0.0, 3.0, 0.9]])
    targets = sphere.targets(np.repeat(points, 100, axis=0), rng).reshape(3, 100 * 64, 3).astype(np.float64)
    for p, target in zip(points, targets, strict=True):
        axis = sphere.c - p
        distance = np.linalg.norm(axis)
        axis /= distance
        np.testing.assert_allclose(np.linalg.norm(target - sphere.c, axis=1), 0.8, rtol=1e-6)
        # On the near side: (q - c).(p - c) >= R^2 (equal on the rim).
        assert np.all((target - sphere.c) @ (p - sphere.c) >= 0.64 * (1 - 1e-5))
        w = (target - p) / np.linalg.norm(target - p, axis=1, keepdims=True)
        u1 = (1.0 - w @ axis) / (1.0 - np.sqrt(1.0 - (0.8 / distance) ** 2))
        # 1 - cos(theta) uniform over the cap: u1 uniform on [0, 1], and per
        # point stratified on the 8 x 8 grid: its j-th smallest u1 in row j // 8.
        assert -1e-4 <= u1.min() and u1.max() <= 1.0 + 1e-4
        rows = np.arange(64) // 8
        ordered = np.sort(u1.reshape(100, 64), axis=1)
        assert np.all((ordered >= rows / 8 - 1e-4) & (ordered <= (rows + 1) / 8 + 1e-4))


def test_scalar_variant_agrees(mitsuba_reference):
    """The scalar fallback (forced in a fresh process) traces the same rays:
    the disk's samples formed there in NumPy float32, the sphere's targets
    passed as they are."""
    script = textwrap.dedent(
        """
        import sys, numpy as np
        sys.path.insert(0, sys.argv[1])
        import test_reference_lights as t
        from softshadow import reference
        images = {name: t.small_render(reference, light) for name, light in t.PLATE_LIGHTS.items()}
        np.savez(sys.argv[2], variant=reference.variant(), **images)
        """
    )
    env = dict(os.environ, SOFTSHADOW_MITSUBA_VARIANT="scalar_rgb")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(ss.__file__).parent.parent)] + sys.path)
    out = Path(os.environ.get("TMPDIR", "/tmp")) / f"softshadow-lights-scalar-{os.getpid()}.npz"
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
    for name, light in PLATE_LIGHTS.items():
        vector = small_render(mitsuba_reference, light)
        assert np.any(vector < 1.0)
        # Same seed, same rays: only rays grazing an edge may differ.
        np.testing.assert_allclose(scalar[name], vector, atol=2 / 16)


def small_render(reference_module, light):
    """A 16x12 view of the plate scene at 16 samples (seed 3): the visibility."""
    cam = camera(**dict(PLATE_CAMERA, resolution=(16, 12)))
    return reference_module.render_visibility(ss.Scene(meshes=PLATE_SCENE), light, cam, 16, seed=3).visibility
