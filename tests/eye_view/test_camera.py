"""The eye view's camera: its documented pixel formula, OpenCV's intrinsics
and Mitsuba's perspective sensor agree ray for ray, and degenerate cameras
are refused by name."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import softshadow as ss


def look(**kw):
    args = dict(eye=(3.0, 2.0, 3.0), target=(0.0, 0.5, 0.0), up=(0.0, 1.0, 0.0), fov_y=40.0, resolution=(64, 48))
    args.update(kw)
    return ss.Camera.look_at(**args)


def test_pixel_centres_follow_the_documented_formula():
    cam = look()
    w, h = cam.resolution
    t = np.tan(np.radians(cam.fov_y) / 2)
    f, r, u = (np.array(v) for v in (cam.forward, cam.right, cam.up))
    assert np.allclose(f, -np.array([3.0, 1.5, 3.0]) / np.linalg.norm([3.0, 1.5, 3.0]))
    assert np.allclose(r, np.cross(f, [0.0, 1.0, 0.0]) / np.linalg.norm(np.cross(f, [0.0, 1.0, 0.0])))
    assert np.allclose(u, np.cross(r, f))
    d = cam.ray_directions()
    for j, i in [(0, 0), (47, 63), (10, 40)]:
        x = (-1 + 2 * (i + 0.5) / w) * t * w / h
        y = (1 - 2 * (j + 0.5) / h) * t
        want = f + x * r + y * u
        np.testing.assert_allclose(d[j, i], want / np.linalg.norm(want), atol=1e-14)
    # Row 0 looks up, column 0 left.
    assert d[0, 32] @ u > 0 and d[24, 0] @ r < 0


def test_from_intrinsics_projects_like_opencv():
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))  # a rotation
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = q, (1.0, -2.0, 0.5)
    K = np.array([[70.0, 0.0, 20.25], [0.0, 70.0, 31.0], [0.0, 0.0, 1.0]])
    cam = ss.Camera.from_intrinsics(K, T, resolution=(64, 48))
    d = cam.ray_directions()
    camera_from_world = np.linalg.inv(T)
    for j, i in [(0, 0), (47, 63), (5, 33)]:
        p = np.append(np.array(cam.eye) + 4.0 * d[j, i], 1.0)
        xc = camera_from_world @ p
        uvw = K @ xc[:3]
        np.testing.assert_allclose(uvw[:2] / uvw[2], (i, j), atol=1e-9)
    k2, t2 = cam.to_opencv()
    np.testing.assert_array_equal(k2, K)
    np.testing.assert_allclose(t2, T, atol=1e-15)
    assert ss.Camera(K, T, resolution=(64, 48)) == cam


@pytest.mark.parametrize(
    "make",
    [
        lambda: look(),
        lambda: look(resolution=(33, 17), fov_y=100.0, up=(0.2, 1.0, -0.1)),
        lambda: ss.Camera.from_intrinsics(
            [[50.0, 0.0, 20.0], [0.0, 50.0, 30.0], [0.0, 0.0, 1.0]],
            [[1.0, 0.0, 0.0, 0.5], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, -2.0], [0.0, 0.0, 0.0, 1.0]],
            resolution=(64, 48),
        ),
    ],
)
def test_mitsuba_samples_the_same_rays_at_pixel_centres(make):
    pytest.importorskip("mitsuba")
    from softshadow.reference._mitsuba import _mitsuba

    mi, _ = _mitsuba()
    cam = make()
    sensor = mi.load_dict(cam.to_mitsuba())
    w, h = cam.resolution
    jj, ii = np.mgrid[0:h, 0:w]
    ray, _ = sensor.sample_ray(
        time=0.0,
        sample1=0.5,
        sample2=mi.Point2f(((ii + 0.5) / w).ravel(), ((jj + 0.5) / h).ravel()),
        sample3=mi.Point2f(0.5, 0.5),
    )
    d = np.array(ray.d).T.reshape(h, w, 3)
    # Mitsuba's rays are float32.
    assert np.abs(d - cam.ray_directions()).max() < 1e-6
    # Its origins lie on the near plane along the same rays.
    o = np.array(ray.o).T.reshape(h, w, 3) - np.array(cam.eye)
    assert np.abs(np.cross(o, cam.ray_directions())).max() < 1e-5


def test_cameras_are_frozen_comparable_and_picklable():
    cam = look()
    assert pickle.loads(pickle.dumps(cam)) == cam
    assert look(fov_y=41.0) != cam
    with pytest.raises(AttributeError):
        cam.fov_y = 3.0  # type: ignore[misc]
    assert "64x48" in repr(cam)


@pytest.mark.parametrize(
    "kw, arg",
    [
        (dict(target=(3.0, 2.0, 3.0)), "target"),
        (dict(up=(3.0, 1.5, 3.0)), "up"),
        (dict(up=(0.0, 0.0, 0.0)), "up"),
        (dict(fov_y=0.0), "fov_y"),
        (dict(fov_y=180.0), "fov_y"),
        (dict(fov_y=float("nan")), "fov_y"),
        (dict(eye=(np.inf, 0.0, 0.0)), "eye"),
        (dict(resolution=(0, 4)), "resolution"),
        (dict(resolution=-3), "resolution"),
    ],
)
def test_degenerate_cameras_are_refused_by_name(kw, arg):
    with pytest.raises(ValueError, match=f"^{arg}: "):
        look(**kw)


def test_absurd_resolutions_are_refused_before_allocating():
    with pytest.raises(ss.TooLargeError, match="^resolution: "):
        look(resolution=(1 << 20, 1 << 20))


def test_intrinsics_with_skew_or_unequal_focals_are_refused():
    T = np.eye(4)
    for K, words in [
        ([[50.0, 1.0, 10.0], [0.0, 50.0, 10.0], [0.0, 0.0, 1.0]], "skew"),
        ([[50.0, 0.0, 10.0], [0.0, 40.0, 10.0], [0.0, 0.0, 1.0]], "fx and fy must be equal"),
        ([[-50.0, 0.0, 10.0], [0.0, -50.0, 10.0], [0.0, 0.0, 1.0]], "focal lengths"),
        ([[50.0, 0.0, 10.0], [0.0, 50.0, 10.0], [0.0, 0.0, 2.0]], "must be"),
    ]:
        with pytest.raises(ValueError, match=f"^K: .*{words}"):
            ss.Camera.from_intrinsics(K, T, resolution=(20, 20))
    scaled = np.diag([2.0, 1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="^world_from_camera: .*rotation"):
        ss.Camera.from_intrinsics(np.diag([50.0, 50.0, 1.0]), scaled, resolution=(20, 20))
    with pytest.raises(TypeError, match="^K: must be a 3x3 matrix"):
        ss.Camera.from_intrinsics("K", T, resolution=(20, 20))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="^world_from_camera: must be a 4x4 matrix"):
        ss.Camera.from_intrinsics(np.diag([50.0, 50.0, 1.0]), np.eye(3), resolution=(20, 20))
