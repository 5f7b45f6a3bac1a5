"""The light frame and its validation."""

import numpy as np
import pytest

import softshadow as ss


def test_frame_follows_the_documented_convention():
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -2, 0), up=(0, 0.5, 3), size=(1.0, 2.0))
    np.testing.assert_allclose(light.n, [0, -1, 0])
    np.testing.assert_allclose(light.v, [0, 0, 1])
    # u = n x v
    np.testing.assert_allclose(light.u, np.cross(light.n, light.v))
    np.testing.assert_allclose(light.u, [-1, 0, 0])
    assert light.area == 2.0
    corners = light.corners()
    np.testing.assert_allclose(corners[2], [0, 4, 0] + 0.5 * light.u + 1.0 * light.v)


def test_scalar_size_means_a_square():
    assert ss.RectLight((0, 0, 0), (0, 0, 1), (0, 1, 0), size=0.5).size == (0.5, 0.5)


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(normal=(0, 0, 0)), ValueError, "normal"),
        (dict(up=(0, 0, 0)), ValueError, "up"),
        (dict(up=(0, -3, 0)), ValueError, "parallel"),
        (dict(size=(0.0, 1.0)), ValueError, "size"),
        (dict(size=(-1.0, 1.0)), ValueError, "size"),
        (dict(size=(1.0, float("inf"))), ValueError, "size"),
        (dict(center=(0, float("nan"), 0)), ValueError, "center"),
        (dict(center=(0, 1)), ValueError, "center"),
        (dict(center="abc"), TypeError, "center"),
    ],
)
def test_bad_lights_are_refused_with_the_argument_named(kwargs, exc, words):
    args = dict(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 1))
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.RectLight(**args)


def test_lights_are_the_core_s_frozen_comparable_picklable_classes():
    import copy
    import pickle

    from softshadow import _core

    assert ss.RectLight is _core.RectLight and ss.DirectionalLight is _core.DirectionalLight
    rect = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 2), radiance=(1, 2, 3))
    sun = ss.DirectionalLight(direction=(0.3, -1, 0.2), up=(0, 0, 1), angular_size=2.0, irradiance=0.5)
    for light in (rect, sun):
        for back in (pickle.loads(pickle.dumps(light)), copy.deepcopy(light), eval(repr(light), vars(ss))):
            assert back == light and hash(back) == hash(light) and back is not light
            np.testing.assert_array_equal(back.n, light.n)
        with pytest.raises(AttributeError):
            light.up = (1, 0, 0)  # type: ignore[misc]
    assert rect != ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1, 2))
    assert rect.radiance == (1.0, 2.0, 3.0) and sun.irradiance == (0.5, 0.5, 0.5)
    assert sun.angular_size == (2.0, 2.0) and rect != sun
    assert repr(rect) == (
        "RectLight(center=(0.0, 4.0, 0.0), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), "
        "size=(1.0, 2.0), radiance=(1.0, 2.0, 3.0))"
    )
    # The frame is a fresh array each time: changing one changes nothing.
    rect.n[0] = 7.0
    assert rect.n[0] == 0.0


def test_disks_and_spheres_are_frozen_comparable_picklable_lights():
    import copy
    import pickle

    disk = ss.DiskLight(center=(0, 4, 0), normal=(0, -2, 0), radius=0.5, radiance=(1, 2, 3))
    sphere = ss.SphereLight(center=(0, 4, 0), radius=0.25, radiance=2.0)
    assert disk.radius == 0.5 and sphere.radiance == (2.0, 2.0, 2.0)
    np.testing.assert_allclose(disk.n, [0, -1, 0])
    # The frame is orthonormal, u = n x v, both in the disk's plane.
    np.testing.assert_allclose(disk.u, np.cross(disk.n, disk.v), atol=1e-15)
    assert abs(float(np.dot(disk.u, disk.n))) < 1e-15 and abs(float(np.dot(disk.v, disk.n))) < 1e-15
    assert disk.area == pytest.approx(np.pi * 0.25) and sphere.area == pytest.approx(4 * np.pi / 16)
    for light in (disk, sphere):
        for back in (pickle.loads(pickle.dumps(light)), copy.deepcopy(light), eval(repr(light), vars(ss))):
            assert back == light and hash(back) == hash(light) and back is not light
        with pytest.raises(AttributeError):
            light.radius = 1.0  # type: ignore[misc]
    assert "radius=0.5" in repr(disk) and disk != ss.DiskLight((0, 4, 0), (0, -1, 0), 0.5)


@pytest.mark.parametrize(
    "make, exc, words",
    [
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), 0.0), ValueError, "radius"),
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), -1.0), ValueError, "radius"),
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), float("nan")), ValueError, "radius"),
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), float("inf")), ValueError, "radius"),
        (lambda: ss.DiskLight((0, 4, 0), (0, 0, 0), 1.0), ValueError, "normal"),
        (lambda: ss.DiskLight((0, float("nan"), 0), (0, -1, 0), 1.0), ValueError, "center"),
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), "big"), TypeError, "radius"),
        (lambda: ss.DiskLight((0, 4, 0), (0, -1, 0), 1.0, radiance=-1.0), ValueError, "radiance"),
        (lambda: ss.SphereLight((0, 4, 0), 0.0), ValueError, "radius"),
        (lambda: ss.SphereLight((0, 4, 0), -0.5), ValueError, "radius"),
        (lambda: ss.SphereLight((0, 4, float("nan")), 1.0), ValueError, "center"),
        (lambda: ss.SphereLight((0, 4, 0), True), TypeError, "radius"),
        (lambda: ss.SphereLight((0, 4, 0), 1.0, radiance=float("nan")), ValueError, "radiance"),
    ],
)
def test_bad_disks_and_spheres_are_refused_by_name(make, exc, words):
    with pytest.raises(exc, match=words):
        make()


def test_the_closed_forms_of_disks_and_spheres_match_a_quadrature():
    # A disk of radius 0.5 at height 2 facing down, seen from points of a
    # tilted floor (some cut by the horizon); a sphere likewise.
    rng = np.random.default_rng(3)
    points = np.c_[rng.uniform(-2, 2, 40), np.zeros(40), rng.uniform(-2, 2, 40)]
    normals = np.tile([0.3, 1.0, -0.2], (40, 1))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    disk = ss.DiskLight((0.4, 2.0, -0.3), (0.2, -1.0, 0.1), 0.5)
    sphere = ss.SphereLight((0.4, 1.2, -0.3), 0.8)
    # The disk by a midpoint rule over its area (polar cells).
    k = 400
    r = (np.arange(k) + 0.5) / k * 0.5
    phi = (np.arange(k) + 0.5) / k * 2 * np.pi
    rr, pp = np.meshgrid(r, phi)
    area = (0.5 / k) * (2 * np.pi / k) * rr
    ys = np.asarray(disk.center) + (rr * np.cos(pp))[..., None] * disk.u + (rr * np.sin(pp))[..., None] * disk.v
    for x, n, got in zip(points, normals, disk.irradiance_at(points, normals)[:, 0], strict=True):
        d = ys - x
        dist = np.linalg.norm(d, axis=-1)
        cos_x = np.clip(d @ n / dist, 0, None)
        cos_l = np.clip(-(d @ disk.n) / dist, 0, None)
        want = float((cos_x * cos_l / dist**2 * area).sum())
        assert got == pytest.approx(want, rel=2e-3, abs=1e-5)
    # The sphere by a midpoint rule over its visible cap (uniform in solid angle).
    for x, n, got in zip(points, normals, sphere.irradiance_at(points, normals)[:, 0], strict=True):
        w = np.asarray(sphere.center) - x
        dist = np.linalg.norm(w)
        w /= dist
        cos_a = np.sqrt(1 - (sphere.radius / dist) ** 2)
        e1 = np.cross(w, [0.0, 0.0, 1.0] if abs(w[2]) < 0.9 else [1.0, 0.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(w, e1)
        t = 1 - (np.arange(k) + 0.5) / k * (1 - cos_a)
        tt, pp2 = np.meshgrid(t, phi)
        s = np.sqrt(1 - tt**2)
        dirs = tt[..., None] * w + (s * np.cos(pp2))[..., None] * e1 + (s * np.sin(pp2))[..., None] * e2
        omega = 2 * np.pi * (1 - cos_a)
        want = float(np.clip(dirs @ n, 0, None).mean() * omega)
        assert got == pytest.approx(want, rel=2e-3, abs=1e-5)
