"""Scenes built as users build them: a floor made of a closed box shadows
what stands on it exactly like a one-sided quad does (src/eye/casters.rs,
the per-triangle caster rule), whatever its winding, and every scene of
``softshadow.scenes.as_built`` builds and renders.

Without the rule, the box floor took texels in the occluder maps and
widened their extent to the whole floor: on the bunny the bitmask's error
over the shadowed pixels went from 0.030 (quad floor) to 0.055, and the
blocks on a box table leaked light in 6.8% of their pixels
(docs/accuracy.md).
"""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss
from softshadow.scenes import as_built, eye_view
from softshadow.scenes.primitives import box, quad

RES = (160, 120)
MAP = (192, 192)


def _floor_variants():
    quad_scene, light, cam = eye_view.bunny_on_floor(RES)
    bunny, quad = quad_scene.meshes
    slab = box((0.0, -0.05, 0.0), (8.0, 0.1, 8.0))
    v, f = slab
    inside_out = (v, f[:, ::-1].copy())
    return bunny, quad, slab, inside_out, light, cam


@pytest.mark.parametrize("method", [ss.Ssm(), ss.Bitmask(), ss.PCSS()], ids=lambda m: m.name)
def test_a_box_floor_shadows_like_a_quad(method):
    bunny, quad, slab, inside_out, light, cam = _floor_variants()
    ref = ss.render(ss.Scene(meshes=[bunny, quad]), light, cam, method=method, map_resolution=MAP)
    for floor in (slab, inside_out):
        img = ss.render(ss.Scene(meshes=[bunny, floor]), light, cam, method=method, map_resolution=MAP)
        # The same surface point in both: the bunny, or the floor's top face.
        same = img.mask & ref.mask & (img.mesh_id == ref.mesh_id)
        same &= np.linalg.norm(np.nan_to_num(img.position - ref.position), axis=-1) < 1e-6
        assert same.sum() > 0.5 * ref.mask.sum()
        np.testing.assert_array_equal(img.visibility[same], ref.visibility[same])
        assert img.map_extent == ref.map_extent


def test_a_box_table_still_shadows_the_floor_and_the_box_floor_casts_nothing():
    # Blocks on a box table over a box floor: the table top's faces still
    # shadow the floor below them; the floor slab (mesh 0) changes nothing
    # of the maps against a quad floor at the same height.
    scene, light, cam = as_built.blocks_on_table(RES)
    quad_floor = ss.Scene(meshes=[quad((0.0, 0.0, 0.0), 4.0), *scene.meshes[1:]])
    img = ss.render(scene, light, cam, method=ss.Ssm(), map_resolution=MAP)
    ref = ss.render(quad_floor, light, cam, method=ss.Ssm(), map_resolution=MAP)
    assert img.map_extent == ref.map_extent
    same = img.mask & ref.mask & (img.mesh_id == ref.mesh_id)
    same &= np.linalg.norm(np.nan_to_num(img.position - ref.position), axis=-1) < 1e-6
    np.testing.assert_array_equal(img.visibility[same], ref.visibility[same])
    under_table = (img.mesh_id == 0) & (img.visibility < 0.5)
    assert under_table.sum() > 100


@pytest.mark.parametrize("name", list(as_built.SCENES))
def test_every_as_built_scene_renders(name):
    scene, light, cam = as_built.SCENES[name](RES)
    assert cam.resolution == RES and scene.triangle_count > 0
    img = ss.render(scene, light, cam, method=ss.Ssm(), map_resolution=(64, 64))
    assert img.visibility.shape == (RES[1], RES[0])
    assert np.all(np.isfinite(img.visibility))
    assert img.mask.mean() > 0.5  # the camera sees the scene


def test_the_sets_are_disjoint_and_hold_eight_each():
    assert len(as_built.CALIBRATION) >= 8 and len(as_built.HELD_OUT) >= 8
    assert not set(as_built.CALIBRATION) & set(as_built.HELD_OUT)
    assert as_built.SCENES == {**as_built.CALIBRATION, **as_built.HELD_OUT}


def test_damaged_meshes_hold_flipped_and_degenerate_faces():
    v, f = as_built.damaged(as_built.suzanne(), seed=1)
    a = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    assert (a == 0).sum() >= 40
    big = [m for m in as_built.crowd(RES)[0].meshes]
    assert sum(len(m[1]) for m in big) > 100_000 and len(big) > 50
