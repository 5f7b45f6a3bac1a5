"""The CPU rasterizer, seen through the depth maps it returns."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes


def sphere_depths(light, extent, res, center, radius):
    """Analytic planar depths (near, far) of a sphere at texel centers."""
    tx, ty = extent
    x = (-1 + 2 * (np.arange(res) + 0.5) / res) * tx
    y = (1 - 2 * (np.arange(res) + 0.5) / res) * ty
    X, Y = np.meshgrid(x, y)
    d = np.stack([X, Y, np.ones_like(X)], -1)  # light-space direction, Z = 1
    s = np.asarray(center) - np.asarray(light.center)
    s = np.array([s @ light.u, s @ light.v, s @ light.n])
    a = (d * d).sum(-1)
    b = -2 * (d @ s)
    c = s @ s - radius**2
    disc = b * b - 4 * a * c
    root = np.sqrt(np.maximum(disc, 0))
    near = np.where(disc > 0, (-b - root) / (2 * a), np.inf)
    far = np.where(disc > 0, (-b + root) / (2 * a), np.inf)
    # Squared half chord (in planar-depth units) and the cosine between the
    # ray and the surface normal where it enters.
    half2 = disc / (4 * a * a)
    cos = np.sqrt(np.maximum(half2 * a, 0)) / radius
    return near, far, half2, cos


@pytest.mark.parametrize("segments, res", [(48, 128), (1000, 256)])
def test_sphere_depth_maps_are_watertight_and_exact(segments, res):
    center, radius = (0.2, 2.0, -0.1), 0.5
    mesh = scenes.sphere(center, radius, n=segments)
    if segments == 1000:
        assert len(mesh[1]) >= 996_000  # the "1M-triangle mesh must work" case
    light = scenes.default_light()
    scene = ss.Scene(occluders=[mesh], receivers=[scenes.floor()])
    extent = (0.45, 0.45)
    sm = ss.soft_shadow_map(scene, light, resolution=res, extent=extent)
    near, far, disc, cos = sphere_depths(light, extent, res, center, radius)
    # Away from the silhouette (where the tessellation's polygon and the
    # sphere differ) every texel is covered: no cracks, no holes.
    inside = disc > 0.05**2 * (2.0**2)
    assert inside.sum() > 0.2 * res * res
    assert np.all(np.isfinite(sm.occluder_depth[inside]))
    assert np.all(np.isfinite(sm.occluder_depth_back[inside]))
    outside = ~np.isfinite(near) | (disc < 0)
    assert np.all(np.isinf(sm.occluder_depth[outside & (disc < -(0.05**2) * 4)]))
    # Depths match the analytic sphere to the tessellation's gap: the facets
    # lie within two sagittas of the sphere, seen along a ray at angle theta
    # to the normal: 2 sag / cos(theta).
    sag = radius * (1 - np.cos(np.pi / segments) * np.cos(2 * np.pi / segments))
    bound = 2 * sag / cos[inside] + 1e-5 * 3
    assert np.all(np.abs(sm.occluder_depth[inside] - near[inside]) < bound)
    assert np.all(np.abs(sm.occluder_depth_back[inside] - far[inside]) < bound)


def test_a_triangle_fan_covers_every_texel_once():
    # A fan of thin triangles around a point: every texel center inside is hit;
    # the depth is the fan's single plane everywhere (no NaN from slivers).
    k = 301
    ang = np.linspace(0, 2 * np.pi, k, endpoint=False)
    rim = np.column_stack([3 * np.cos(ang), np.full(k, 2.0), 3 * np.sin(ang)])
    verts = np.vstack([[0.01, 2.0, -0.02], rim])
    faces = np.array([[0, 1 + s, 1 + (s + 1) % k] for s in range(k)])
    scene = ss.Scene(occluders=[(verts, faces)], receivers=[scenes.floor()])
    sm = ss.soft_shadow_map(scene, scenes.default_light(), resolution=200, extent=0.8)
    np.testing.assert_allclose(sm.occluder_depth, 2.0, rtol=1e-6)
    np.testing.assert_allclose(sm.occluder_depth_back, 2.0, rtol=1e-6)


def test_receivers_partly_behind_the_light_are_clipped():
    # A wall crossing the light's plane: the part in front is rasterized.
    wall = (np.array([[-3, -1, 3.0], [3, -1, 3.0], [3, 8, 3.0], [-3, 8, 3.0]]), [[0, 1, 2], [0, 2, 3]])
    scene = ss.Scene(occluders=[scenes.quad((0, 2, 1.5), 0.3)], receivers=[scenes.floor(), wall])
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 1), up=(0, 1, 1), size=0.5)
    sm = ss.soft_shadow_map(scene, light, resolution=64, extent=(1.0, 1.0))
    d = sm.receiver_depth
    assert np.all(np.isinf(d) | ((d > 0) & np.isfinite(d)))
    assert np.isfinite(d).mean() > 0.5
    assert np.all((sm.visibility >= 0) & (sm.visibility <= 1))
