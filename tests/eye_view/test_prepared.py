"""A scene prepared once for many renders (issue 29, item 3): ``Scene``
keeps the checked triangles and the shadow rays' tree per light orientation,
refits the tree to the next camera, starts again when a mesh changes, and
never changes an answer."""

from __future__ import annotations

import pickle
import threading

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes


def _meshes() -> list[tuple[np.ndarray, np.ndarray]]:
    v, f = scenes.bunny_mesh(height=1.0, base=1.0)
    return [(v.copy(), f), scenes.quad((0.0, 0.0, 0.0), 3.0)]


LIGHT = ss.RectLight(center=(0.6, 4.0, 0.3), normal=(-0.1, -1.0, -0.05), up=(0, 0, 1), size=(1.2, 1.2))
TURNED = ss.RectLight(center=(2.0, 3.0, 0.3), normal=(-0.6, -1.0, 0.0), up=(0, 0, 1), size=(1.2, 1.2))
SUN = ss.DirectionalLight(direction=(0.5, -1.0, -0.3), up=(0, 0, 1), angular_size=(2.0, 2.0))


def _camera(eye: tuple[float, float, float]) -> ss.Camera:
    return ss.Camera.look_at(eye=eye, target=(0, 0.4, 0), up=(0, 1, 0), fov_y=40.0, resolution=(96, 72))


CAMERAS = [_camera((2.2, 1.6, 2.8)), _camera((-2.5, 2.0, 1.5)), _camera((0.5, 3.0, -2.6))]
METHOD = ss.Exact(samples=16)


def _fresh(meshes: list[tuple[np.ndarray, np.ndarray]], light: object, camera: ss.Camera) -> np.ndarray:
    """The visibility with nothing prepared (a new scene each time)."""
    return ss.render(ss.Scene(meshes=meshes), light, camera, method=METHOD).visibility


@pytest.mark.parametrize("light", [LIGHT, SUN], ids=["rect", "sun"])
def test_later_cameras_refit_the_kept_tree_and_see_what_a_fresh_scene_sees(light: object) -> None:
    meshes = _meshes()
    scene = ss.Scene(meshes=meshes)
    assert scene.prepared.held == (False, 0)
    for k, cam in enumerate(CAMERAS):
        img = ss.render(scene, light, cam, method=METHOD)
        # The first call builds the tree; the others refit it.
        assert ("bvh" in img.timings) == (k == 0), img.timings
        assert ("refit" in img.timings) == (k > 0), img.timings
        np.testing.assert_array_equal(img.visibility, _fresh(meshes, light, cam))
    assert scene.prepared.held == (True, 1)


def test_the_default_call_and_a_target_read_the_preparation_too() -> None:
    scene = ss.Scene(meshes=_meshes())
    ss.render(scene, LIGHT, CAMERAS[0])
    again = ss.render(scene, LIGHT, CAMERAS[1])
    assert "refit" in again.timings
    target = ss.render(scene, LIGHT, CAMERAS[2], method=ss.Auto(error=0.02))
    # Its runs share one tree (the first run's refit; a refinement's image
    # times its own stages only), still the one kept.
    assert "bvh" not in target.timings
    assert scene.prepared.held == (True, 1)
    fresh = ss.render(ss.Scene(meshes=scene.meshes), LIGHT, CAMERAS[2], method=ss.Auto(error=0.02))
    np.testing.assert_array_equal(target.visibility, fresh.visibility)


def test_a_light_turned_another_way_builds_its_own_tree_and_both_are_kept() -> None:
    scene = ss.Scene(meshes=_meshes())
    cam = CAMERAS[0]
    assert "bvh" in ss.render(scene, LIGHT, cam, method=METHOD).timings
    turned = ss.render(scene, TURNED, cam, method=METHOD)
    assert "bvh" in turned.timings
    np.testing.assert_array_equal(turned.visibility, _fresh(scene.meshes, TURNED, cam))
    assert scene.prepared.held == (True, 2)
    # The same orientation, moved: the first tree, refitted.
    moved = ss.RectLight(center=(-0.5, 3.5, 0.8), normal=LIGHT.normal, up=LIGHT.up, size=(0.5, 0.8))
    img = ss.render(scene, moved, CAMERAS[1], method=METHOD)
    assert "refit" in img.timings
    np.testing.assert_array_equal(img.visibility, _fresh(scene.meshes, moved, CAMERAS[1]))


def test_a_mesh_changed_in_place_is_another_scene() -> None:
    meshes = _meshes()
    scene = ss.Scene(meshes=meshes)
    before = ss.render(scene, LIGHT, CAMERAS[0], method=METHOD)
    # Lift the bunny in place: the scene's own array changes under it.
    scene.meshes[0][0][:, 1] += 0.5
    after = ss.render(scene, LIGHT, CAMERAS[0], method=METHOD)
    assert "bvh" in after.timings and "refit" not in after.timings
    assert not np.array_equal(before.visibility, after.visibility)
    np.testing.assert_array_equal(after.visibility, _fresh(scene.meshes, LIGHT, CAMERAS[0]))
    # A mesh appended: again another scene.
    scene.meshes.append(scenes.quad((0.0, 2.5, 0.0), 0.2))
    added = ss.render(scene, LIGHT, CAMERAS[0], method=METHOD)
    assert "bvh" in added.timings
    np.testing.assert_array_equal(added.visibility, _fresh(scene.meshes, LIGHT, CAMERAS[0]))


def test_threads_share_one_preparation_and_get_the_answers_one_thread_gets() -> None:
    scene = ss.Scene(meshes=_meshes())
    expected = [_fresh(scene.meshes, light, cam) for light in (LIGHT, TURNED) for cam in CAMERAS]
    got: dict[int, np.ndarray] = {}
    errors: list[BaseException] = []

    def work(k: int) -> None:
        try:
            light, cam = [(light, cam) for light in (LIGHT, TURNED) for cam in CAMERAS][k % 6]
            got[k] = ss.render(scene, light, cam, method=METHOD, threads=1).visibility
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for k in range(12):
        np.testing.assert_array_equal(got[k], expected[k % 6])
    assert scene.prepared.held == (True, 2)


def test_pickling_keeps_the_meshes_and_drops_the_preparation() -> None:
    scene = ss.Scene(meshes=_meshes())
    ss.render(scene, LIGHT, CAMERAS[0], method=METHOD)
    copy = pickle.loads(pickle.dumps(scene))
    assert copy.prepared.held == (False, 0)
    np.testing.assert_array_equal(
        ss.render(copy, LIGHT, CAMERAS[1], method=METHOD).visibility,
        ss.render(scene, LIGHT, CAMERAS[1], method=METHOD).visibility,
    )
    scene.prepared.clear()
    assert scene.prepared.held == (False, 0)
    assert "Prepared(" in repr(scene.prepared)
