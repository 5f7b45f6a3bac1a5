"""Shaded images: the closed-form irradiance, the per-pixel shading, Mitsuba's ``direct``.

The bounds against Mitsuba were measured first (80x60, ``exact`` at 256
samples against Mitsuba's ``direct`` at 256 samples per pixel, seeds 0 and
1; docs/shading.md): ``mean|shaded - mitsuba| / mean(mitsuba)`` over the hit
pixels is 0.00072 on bunny_on_floor, 0.00135 on torus_self and 0.00053 on
city under a hard sun, Mitsuba's own noise (seed 0 against seed 1) 0.00055,
0.00134 and 0. With exact's samples weighted alike (``unshadowed *
visibility``, before issue 31) it was 0.00135, 0.00315 and 0.00053; without
the shadows (``unshadowed``) 0.022, 0.167 and 0.213.
"""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes

RNG_SEED = 11


def _light() -> ss.RectLight:
    return ss.RectLight(center=(0.2, 2.0, -0.1), normal=(0.1, -1.0, 0.2), up=(0, 0, 1), size=(1.0, 0.6), radiance=1.0)


def _quadrature(light: ss.RectLight, points: np.ndarray, normals: np.ndarray, k: int = 400) -> np.ndarray:
    """Irradiance of a unit-radiance rectangle by a midpoint rule over its area:
    ``sum cos_x+ cos_l+ / r^2 dA``, the point's cosine clamped at its horizon."""
    t = (np.arange(k) + 0.5) / k - 0.5
    s_grid, t_grid = np.meshgrid(t * light.size[0], t * light.size[1], indexing="ij")
    samples = np.asarray(light.center) + s_grid.reshape(-1, 1) * light.u + t_grid.reshape(-1, 1) * light.v
    d_area = light.area / k**2
    out = np.empty(len(points))
    for i, (x, n) in enumerate(zip(points, normals, strict=True)):
        d = samples - x
        r2 = np.einsum("ij,ij->i", d, d)
        w = d / np.sqrt(r2)[:, None]
        cos_x = np.maximum(w @ n, 0.0)
        cos_l = np.maximum(-(w @ light.n), 0.0)
        out[i] = np.sum(cos_x * cos_l / r2) * d_area
    return out


def test_rectangle_closed_form_matches_quadrature_with_horizon_clipping():
    light = _light()
    rng = np.random.default_rng(RNG_SEED)
    # Points in front of the light, 0.3 to 2.5 from its plane, and unit normals
    # uniform on the sphere: many see the light cut by their horizon.
    q = np.column_stack([rng.uniform(-1.5, 1.5, 60), rng.uniform(-1.5, 1.5, 60), rng.uniform(0.3, 2.5, 60)])
    points = np.asarray(light.center) + q[:, :1] * light.u + q[:, 1:2] * light.v + q[:, 2:] * light.n
    normals = rng.normal(size=(60, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    corners = light.corners()
    side = np.einsum("cij,ij->ci", corners[:, None, :] - points[None], normals)
    clipped = np.any(side > 0, axis=0) & np.any(side < 0, axis=0)
    assert clipped.sum() >= 15, "the cases must include lights cut by the horizon"

    got = light.irradiance_at(points, normals * 3.0)[:, 0]  # any length of normal
    want = _quadrature(light, points, normals)
    np.testing.assert_allclose(got, want, rtol=2e-3, atol=2e-5)
    assert np.any(want[clipped] > 1e-3) and np.any(want == 0.0)


def test_points_at_or_behind_the_light_get_nothing_and_emission_scales():
    light = _light()
    on_plane = np.asarray(light.center) + 0.3 * light.u
    behind = np.asarray(light.center) - 0.5 * light.n
    facing_light = -light.n  # a normal facing the light's emitting side
    e = light.irradiance_at([on_plane, behind], [facing_light, facing_light])
    assert np.all(e == 0.0)
    coloured = ss.RectLight(light.center, light.normal, light.up, light.size, radiance=(0.5, 2.0, 0.0))
    x = np.asarray(light.center) + 1.0 * light.n
    grey = light.irradiance_at([x], [-light.n])[0, 0]
    assert grey > 0.1
    np.testing.assert_allclose(coloured.irradiance_at([x], [-light.n])[0], [0.5 * grey, 2.0 * grey, 0.0], rtol=1e-12)


def test_sun_closed_form_is_the_cosine_toward_its_centre():
    sun = ss.DirectionalLight(direction=(0.3, -1.0, 0.2), up=(0, 0, 1), angular_size=0.53, irradiance=(1.0, 2.0, 3.0))
    rng = np.random.default_rng(RNG_SEED)
    normals = rng.normal(size=(200, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points = rng.uniform(-5, 5, size=(200, 3))
    want = np.maximum(normals @ -sun.n, 0.0)[:, None] * np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(sun.irradiance_at(points, normals), want, rtol=1e-12, atol=1e-15)
    assert np.any(want == 0.0) and np.any(want > 0.5)


def _two_mesh_scene() -> tuple[ss.Scene, ss.Camera]:
    plate = scenes.quad((0.0, 0.8, 0.0), 0.35)
    floor = scenes.quad((0.0, 0.0, 0.0), 2.0)
    cam = ss.Camera.look_at(eye=(1.6, 2.2, 2.4), target=(0.0, 0.2, 0.0), up=(0, 1, 0), fov_y=40.0, resolution=(64, 48))
    return ss.Scene(meshes=[plate, floor]), cam


LIGHTS = {
    "rect": ss.RectLight(
        center=(0.3, 2.0, 0.2), normal=(-0.3, -2.0, -0.2), up=(0, 0, 1), size=0.7, radiance=(2, 1, 0.5)
    ),
    "sun": ss.DirectionalLight(direction=(0.4, -1.0, 0.3), up=(0, 0, 1), angular_size=4.0, irradiance=(1, 2, 3)),
}
ALBEDO = [(0.2, 0.4, 0.6), 0.9]


@pytest.mark.parametrize("light", LIGHTS.values(), ids=LIGHTS.keys())
@pytest.mark.parametrize("method", ["exact", "ssm", "bitmask", ss.PCSS(), ss.ShadowMapping()], ids=str)
def test_shaded_is_unshadowed_times_visibility_with_each_mesh_albedo(light, method):
    scene, cam = _two_mesh_scene()
    img = ss.render(scene, light, cam, method=method, albedo=ALBEDO)
    assert img.shaded.dtype == np.float32 and img.shaded.shape == (48, 64, 3)
    assert img.unshadowed.dtype == np.float32 and img.unshadowed.shape == (48, 64, 3)
    m = img.mask
    assert np.all(img.shaded[~m] == 0.0) and np.all(img.unshadowed[~m] == 0.0)
    assert set(np.unique(img.mesh_id[m])) == {0, 1}
    # unshadowed = albedo of the pixel's mesh / pi * E(position, normal).
    e = light.irradiance_at(img.position[m], img.normal[m].astype(np.float64))
    albedo = np.array([ALBEDO[0], (ALBEDO[1],) * 3])[img.mesh_id[m]]
    np.testing.assert_allclose(img.unshadowed[m], albedo / np.pi * e, rtol=1e-6, atol=1e-9)
    weighs = method in ("exact", "ssm", "bitmask") or isinstance(method, ss.PCSS)
    if weighs and isinstance(light, ss.RectLight):
        # Each of exact's rays, the SSM's micro-patches, the bitmask's
        # light samples and PCSS's filter cells weighs what it adds to the
        # irradiance: shaded = unshadowed * V_w,
        # V_w equal to V where V is 0 or 1 and near it in penumbrae (the
        # light's near part weighs more).
        full = m & ((img.visibility == 0.0) | (img.visibility == 1.0))
        np.testing.assert_allclose(
            img.shaded[full], (img.unshadowed * img.visibility[..., None])[full], rtol=1e-6, atol=1e-9
        )
        lit = m & (img.unshadowed[..., 0] > 1e-3)
        ratio = img.shaded[lit, 0] / img.unshadowed[lit, 0]
        assert np.all((ratio >= 0.0) & (ratio <= 1.0 + 1e-6))
        penumbra = (img.visibility[lit] > 0.0) & (img.visibility[lit] < 1.0)
        assert penumbra.sum() > 20
        diff = ratio[penumbra] - img.visibility[lit][penumbra]
        assert np.abs(diff).max() < 0.3 and np.abs(diff).mean() > 1e-3
    else:
        np.testing.assert_allclose(img.shaded, img.unshadowed * img.visibility[..., None], rtol=1e-6, atol=1e-9)
    # Some pixels are shadowed, some lit, and the lit ones are not black.
    assert np.any(m & (img.visibility < 0.5)) and np.any(img.shaded[m].max(axis=1) > 0.01)
    assert "shading" in img.timings


def test_default_albedo_is_grey_and_channels_hold_the_shaded_images():
    scene, cam = _two_mesh_scene()
    light = LIGHTS["rect"]
    default = ss.render(scene, light, cam, method="exact")
    grey = ss.render(scene, light, cam, method="exact", albedo=0.8)
    np.testing.assert_array_equal(default.shaded, grey.shaded)
    channels = default.channels()
    for k, c in enumerate("RGB"):
        np.testing.assert_array_equal(channels[f"shaded.{c}"], default.shaded[..., k])
        np.testing.assert_array_equal(channels[f"unshadowed.{c}"], default.unshadowed[..., k])
    # An RGB triple for all meshes, and numpy albedos.
    rgb = ss.render(scene, light, cam, method="exact", albedo=np.array([0.8, 0.4, 0.0]))
    np.testing.assert_allclose(rgb.shaded[..., 1], 0.5 * grey.shaded[..., 1], rtol=1e-6)
    assert np.all(rgb.shaded[..., 2] == 0.0)


@pytest.mark.gpu
@pytest.mark.skipif(not ss.gpu_available(), reason="no GPU adapter")
@pytest.mark.parametrize(
    "method", [ss.Exact(), ss.Ssm(), ss.Bitmask(hierarchy=False), ss.PCSS()], ids=["exact", "ssm", "bitmask", "pcss"]
)
def test_gpu_shades_as_the_cpu_does(method):
    scene, cam = _two_mesh_scene()
    light = LIGHTS["rect"]
    img = ss.render(scene, light, cam, method=method, albedo=ALBEDO, backend="gpu")
    assert img.backend == "gpu"
    m = img.mask
    e = light.irradiance_at(img.position[m], img.normal[m].astype(np.float64))
    albedo = np.array([ALBEDO[0], (ALBEDO[1],) * 3])[img.mesh_id[m]]
    np.testing.assert_allclose(img.unshadowed[m], albedo / np.pi * e, rtol=1e-6, atol=1e-9)
    # The device weighs its samples as the CPU does (its sums in f32, the
    # CPU's in f64): the same shaded image to rounding.
    cpu = ss.render(scene, light, cam, method=method, albedo=ALBEDO)
    both = m & cpu.mask
    if isinstance(method, (ss.Ssm, ss.PCSS)):
        # The SSM's and PCSS's f32 sums round differently on the device
        # (measured here on lavapipe: at most 6.0e-8 and 4.2e-7).
        np.testing.assert_allclose(img.visibility[both], cpu.visibility[both], rtol=0, atol=1e-6)
    else:
        np.testing.assert_array_equal(img.visibility[both], cpu.visibility[both])
    np.testing.assert_allclose(img.shaded[both], cpu.shaded[both], rtol=1e-4, atol=1e-7)
    assert not np.allclose(img.shaded, img.unshadowed * img.visibility[..., None], rtol=1e-3, atol=1e-6)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(albedo=1.5), "albedo"),
        (dict(albedo=-0.1), "albedo"),
        (dict(albedo=float("nan")), "albedo"),
        (dict(albedo=[]), "albedo"),  # neither a triple nor one per mesh
        (dict(albedo=[0.5, 0.5, 0.5, 0.5]), "albedo"),  # 4 values, 2 meshes
        (dict(albedo=[0.5, (0.1, 2.0, 0.1)]), r"albedo\[1\]"),
        (dict(albedo=[0.5, (0.1, 0.2)]), r"albedo\[1\]"),
    ],
)
def test_bad_albedo_is_refused_naming_it(kwargs, words):
    scene, cam = _two_mesh_scene()
    with pytest.raises(ValueError, match=words):
        ss.render(scene, LIGHTS["rect"], cam, method="exact", **kwargs)


@pytest.mark.parametrize("value", [-1.0, (1.0, -0.5, 1.0), float("nan"), float("inf"), (1.0, 2.0)])
def test_bad_emission_is_refused_naming_it(value):
    with pytest.raises(ValueError, match="radiance"):
        ss.RectLight((0, 2, 0), (0, -1, 0), (0, 0, 1), 1.0, radiance=value)
    with pytest.raises(ValueError, match="irradiance"):
        ss.DirectionalLight((0, -1, 0), (0, 0, 1), irradiance=value)


def test_wrong_types_are_refused_naming_the_argument():
    scene, cam = _two_mesh_scene()
    with pytest.raises(TypeError, match="albedo"):
        ss.render(scene, LIGHTS["rect"], cam, method="exact", albedo="grey")
    with pytest.raises(TypeError, match="radiance"):
        ss.RectLight((0, 2, 0), (0, -1, 0), (0, 0, 1), 1.0, radiance="bright")
    with pytest.raises(ValueError, match="normals"):
        LIGHTS["rect"].irradiance_at([[0, 0, 0]], [[0, 0, 0]])


# --------------------------------------------------------------------------
# Against Mitsuba's direct integrator
# --------------------------------------------------------------------------


def _relative_error(ours: np.ndarray, mitsuba: np.ndarray, mask: np.ndarray) -> float:
    return float(np.abs(ours[mask] - mitsuba[mask]).mean() / mitsuba[mask].mean())


def test_mitsuba_emitters_match_the_closed_form_where_nothing_occludes():
    """The area emitter's orientation and radiance, and the directional
    emitter's irradiance, are ours: an unoccluded tilted plane."""
    pytest.importorskip("mitsuba")
    from softshadow.reference import render_direct

    plane = scenes.quad((0.0, 0.0, 0.0), 1.5)
    tilted = (
        plane[0] @ np.array([[1, 0, 0], [0, np.cos(0.4), -np.sin(0.4)], [0, np.sin(0.4), np.cos(0.4)]]).T,
        plane[1],
    )
    scene = ss.Scene(meshes=[tilted])
    cam = ss.Camera.look_at(eye=(0.5, 3.0, 2.5), target=(0, 0, 0), up=(0, 1, 0), fov_y=40.0, resolution=(64, 48))
    rect = ss.RectLight((0.6, 1.2, 0.3), (-0.6, -1.2, -0.5), (0, 0, 1), (0.8, 0.5), radiance=(1.0, 2.0, 3.0))
    sun = ss.DirectionalLight((0.5, -1.0, -0.4), (0, 0, 1), angular_size=0.0, irradiance=(3.0, 2.0, 1.0))
    for light, bound in ((rect, 3e-3), (sun, 1e-5)):
        img = ss.render(scene, light, cam, method="exact", albedo=(0.5, 0.6, 0.7))
        ref = render_direct(scene, light, cam, albedo=(0.5, 0.6, 0.7), samples=256, seed=0)
        m = img.mask
        assert m.sum() > 1000 and np.all(img.visibility[m] == 1.0)
        assert np.all(ref[~m] == 0.0)
        assert _relative_error(img.shaded, ref, m) < bound
        # No bias in any channel (a wrong side or convention would be far off).
        bias = (img.shaded[m] - ref[m]).mean(axis=0) / ref[m].mean(axis=0)
        assert np.all(np.abs(bias) < bound / 3)


MITSUBA_BOUNDS = {"bunny_on_floor": 0.0012, "torus_self": 0.0025, "city": 0.0015}


@pytest.mark.parametrize("name", MITSUBA_BOUNDS)
def test_exact_shading_is_near_mitsuba_direct(name):
    pytest.importorskip("mitsuba")
    from softshadow.reference import render_direct

    scene, light, cam = getattr(scenes.eye_view, name)((80, 60))
    if isinstance(light, ss.DirectionalLight):
        # Mitsuba's directional emitter is a delta direction: a hard sun.
        light = ss.DirectionalLight(light.direction, light.up, angular_size=0.0, irradiance=(1.0, 0.9, 0.8))
        albedo: object = None
    else:
        light = ss.RectLight(light.center, light.normal, light.up, light.size, radiance=(2.0, 1.5, 1.0))
        albedo = [(0.9, 0.6, 0.3)] + [0.5] * (len(scene.meshes) - 1)
    img = ss.render(scene, light, cam, method=ss.Exact(samples=256), albedo=albedo)
    ref = render_direct(scene, light, cam, albedo=albedo, samples=256, seed=0)
    m = img.mask
    assert np.all(ref[~m] == 0.0)
    error = _relative_error(img.shaded, ref, m)
    assert error < MITSUBA_BOUNDS[name]
    # The shadows matter: without them the error is 7 to 140 times larger.
    assert _relative_error(img.unshadowed, ref, m) > 5 * MITSUBA_BOUNDS[name]


def _weighted_and_alike_under_contact_boxes(method: object, shape: str) -> tuple[float, float]:
    """The relative error against Mitsuba's ``direct`` (1024 samples) of
    ``method``'s shaded image under ``contact_boxes``' large close light
    (2.5 wide, 2 above the floor, where the light's parts weigh most
    unevenly; ``disk``: the disk of its area), at 80x60, and of its
    visibility weighted alike."""
    pytest.importorskip("mitsuba")
    from softshadow.reference import render_direct

    scene, light, cam = scenes.eye_view.contact_boxes((80, 60))
    if shape == "disk":
        light = ss.DiskLight(light.center, light.normal, float(np.sqrt(light.size[0] * light.size[1] / np.pi)))
    img = ss.render(scene, light, cam, method=method)
    ref = render_direct(scene, light, cam, samples=1024, seed=0)
    m = img.mask
    weighted = _relative_error(img.shaded, ref, m)
    alike = _relative_error(img.unshadowed * img.visibility[..., None], ref, m)
    return weighted, alike


@pytest.mark.parametrize("shape", ["rect", "disk"])
def test_bitmask_weighs_its_samples_near_mitsuba_direct(shape):
    """Measured: the bitmask (1024 samples, its samples weighted) 0.0132
    (rect) and 0.0158 (disk), the rest its visibility's error (0.0067 on
    512-texel maps); its visibility weighted alike 0.0699 and 0.0756;
    Mitsuba's noise 0.0021."""
    weighted, alike = _weighted_and_alike_under_contact_boxes(ss.Bitmask(samples=1024), shape)
    assert weighted < 0.02 and alike > 0.05
    assert weighted < 0.3 * alike


@pytest.mark.parametrize("shape", ["rect", "disk"])
def test_pcss_weighs_its_filter_cells_near_mitsuba_direct(shape):
    """PCSS weighs each cell of its filter by the light point it stands for
    (methods/pcss_weighted.rs). Measured: 0.0220 (rect) and 0.0215 (disk),
    where its visibility weighted alike errs 0.0771 and 0.0789 (the rest is
    its visibility's error: one mean blocker depth per pixel)."""
    weighted, alike = _weighted_and_alike_under_contact_boxes(ss.PCSS(), shape)
    assert weighted < 0.03 and alike > 0.07
    assert weighted < 0.35 * alike


def test_ssm_weighs_its_micro_patches_near_mitsuba_direct():
    """The SSM weighs each micro-patch's back-projection at its centre.
    Measured under the rectangle: 0.0250, where its visibility weighted
    alike errs 0.0845 (the rest is its visibility's error: overlapping
    back-projections counted twice, §3.4)."""
    weighted, alike = _weighted_and_alike_under_contact_boxes("ssm", "rect")
    assert weighted < 0.035 and alike > 0.07
    assert weighted < 0.4 * alike
