"""Exact(engine="masks"): each receiver's samples marked by the triangles that
cross its light, against the rays on the same samples (the same bits but for
rays that graze an edge)."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes
from softshadow.scenes import as_built

#: The share of pixels (texels) whose visibility the two engines may give
#: differently: the rays that graze an edge (issue 50's bar: 99.9% equal).
SAME = 0.999


def same_share(a: np.ndarray, b: np.ndarray, where: np.ndarray) -> float:
    return float((a == b)[where].mean())


@pytest.mark.parametrize("name", ["blocks_on_table", "fence_slats", "open_assets"])
@pytest.mark.parametrize("samples", [64, 256, 1024])
def test_the_eye_view_gives_the_rays_bits(name, samples):
    # Closed boxes in contact, thin slats, open and flipped meshes.
    scene, light, cam = as_built.SCENES[name]((64, 48))
    rays = ss.render(scene, light, cam, method=ss.Exact(samples=samples, engine="rays"))
    masks = ss.render(scene, light, cam, method=ss.Exact(samples=samples, engine="masks"))
    seen = np.isfinite(rays.depth)
    penumbra = seen & (rays.visibility > 0) & (rays.visibility < 1)
    assert penumbra.sum() > 50  # the scene has penumbrae to get wrong
    assert same_share(rays.visibility, masks.visibility, seen) >= SAME
    # A pixel that differs differs by a grazing sample or two.
    assert np.abs(rays.visibility - masks.visibility).max() <= 2 / samples
    # The shaded image weighs the same samples.
    assert np.abs(rays.shaded - masks.shaded)[seen].max() <= 4 / samples * max(1.0, float(rays.shaded.max()))
    assert masks.method.engine == "masks" and rays.method.engine == "rays"


def turned_boxes() -> ss.Scene:
    """Closed boxes as users stack them (the masks mark each by its outline):
    thin turned slats and panels crossing each other, one box wound inside
    out, two stacked on shared corners, a floor slab; and an open box and a
    merged multi-box mesh beside them, which are not pieces."""
    from softshadow.scenes.primitives import box, rotated

    rng = np.random.default_rng(5)
    meshes = [as_built.slab()]
    for k in range(18):
        c = (float(rng.uniform(-1, 1)), float(rng.uniform(0.4, 1.4)), float(rng.uniform(-1, 1)))
        size = [(1.2, 0.02, 0.1), (0.5, 0.4, 0.03), (0.2, 0.25, 0.2)][k % 3]
        m = rotated(rotated(box(c, size), float(rng.uniform(0, 180)), "x"), float(rng.uniform(0, 180)), "y")
        if k == 4:
            m = (m[0], m[1][:, ::-1].copy())
        meshes.append(m)
    meshes += [box((0.6, 0.1, 0.6), (0.2, 0.2, 0.2)), box((0.6, 0.3, 0.6), (0.2, 0.2, 0.2))]
    v, f = box((-0.6, 0.3, 0.6), (0.4, 0.3, 0.2))
    meshes.append((v, f[:10]))
    (va, fa), (vb, fb) = box((0.0, 0.2, -0.6), (0.3, 0.1, 0.3)), box((0.0, 0.35, -0.6), (0.1, 0.2, 0.1))
    meshes.append((np.vstack([va, vb]), np.vstack([fa, fb + len(va)])))
    return ss.Scene(meshes=meshes)


def assert_both_views_give_the_rays_bits(scene: ss.Scene, samples: int, target: tuple[float, float, float]) -> None:
    """The eye view (penumbrae to get wrong, 99.9% the same bits, a differing
    pixel off by a grazing sample or two) and the light view, whose
    receivers lie on the occluders themselves (one origin each)."""
    light = as_built.rect_light((0.3, 2.4, 0.2), (0.0, 0.0, 0.0), (1.2, 0.9))
    cam = ss.Camera.look_at(eye=(2.2, 1.8, 2.4), target=target, up=(0, 1, 0), fov_y=45.0, resolution=(64, 48))
    rays = ss.render(scene, light, cam, method=ss.Exact(samples=samples, engine="rays"))
    masks = ss.render(scene, light, cam, method=ss.Exact(samples=samples, engine="masks"))
    seen = np.isfinite(rays.depth)
    assert ((rays.visibility > 0) & (rays.visibility < 1)).sum() > 200
    assert same_share(rays.visibility, masks.visibility, seen) >= SAME
    assert np.abs(rays.visibility - masks.visibility).max() <= 2 / samples
    a = ss.soft_shadow_map(scene, light, resolution=48, method=ss.Exact(samples=samples, engine="rays"))
    b = ss.soft_shadow_map(scene, light, resolution=48, method=ss.Exact(samples=samples, engine="masks"))
    on = np.isfinite(a.receiver_depth)
    assert same_share(a.visibility, b.visibility, on) >= SAME


@pytest.mark.parametrize("samples", [256, 1024])
def test_closed_boxes_marked_by_their_outline_give_the_rays_bits(samples):
    assert_both_views_give_the_rays_bits(turned_boxes(), samples, (0.0, 0.4, 0.0))


def rounded_solids() -> ss.Scene:
    """Closed convex meshes of many triangles as trimesh makes them (the masks
    mark each by its silhouette): icospheres, a UV sphere, a cylinder and a
    capsule, one sphere wound inside out, one sunk into the floor and one
    through another; and closed meshes that are not convex beside them (a
    torus, a dented sphere), which are marked triangle by triangle."""
    import trimesh

    def m(t: trimesh.Trimesh, at: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(t.vertices) + np.asarray(at), np.asarray(t.faces)

    flipped = trimesh.creation.icosphere(subdivisions=2, radius=0.2)
    flipped.invert()
    dented = trimesh.creation.icosphere(subdivisions=2, radius=0.25)
    v = np.asarray(dented.vertices).copy()
    v[7] *= 0.6
    meshes = [
        as_built.slab(),
        m(trimesh.creation.icosphere(subdivisions=3, radius=0.3), (-0.5, 0.6, 0.0)),
        m(trimesh.creation.uv_sphere(radius=0.25, count=[24, 24]), (0.4, 0.9, -0.2)),
        m(trimesh.creation.cylinder(radius=0.12, height=0.8, sections=40), (0.1, 0.5, 0.5)),
        m(trimesh.creation.capsule(height=0.5, radius=0.1, count=[16, 16]), (-0.2, 1.2, -0.5)),
        m(flipped, (0.7, 0.4, 0.5)),
        m(trimesh.creation.icosphere(subdivisions=2, radius=0.3), (-0.8, 0.1, -0.6)),
        m(trimesh.creation.icosphere(subdivisions=2, radius=0.2), (-0.35, 0.75, 0.2)),
        m(trimesh.creation.torus(major_radius=0.25, minor_radius=0.07), (0.6, 1.3, 0.0)),
        (v + np.array([0.0, 1.0, -0.9]), np.asarray(dented.faces)),
    ]
    return ss.Scene(meshes=meshes)


@pytest.mark.parametrize("samples", [256, 1024])
def test_solids_marked_by_their_silhouette_give_the_rays_bits(samples):
    assert_both_views_give_the_rays_bits(rounded_solids(), samples, (0.0, 0.5, 0.0))


def test_a_dense_bumpy_mesh_left_to_the_rays_gives_their_bits():
    """A non-convex mesh of 80 000 triangles, each one's shadow far smaller
    than a cell of the pattern: the receivers in its shadow pass the masks'
    budget and are traced instead, the others marked (365 of the 2 205 eye-
    view receivers and 30 of the 2 304 texels when written, counted in
    `engine.rs`; the Rust test asserts that some are left); both views
    agree."""
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=6, radius=0.45)
    v = np.asarray(ball.vertices)
    bumps = 1.0 + 0.04 * np.sin(9.0 * v[:, 0] / 0.45) * np.cos(7.0 * v[:, 1] / 0.45)
    v = v * bumps[:, None] + np.array([0.0, 0.6, 0.0])
    scene = ss.Scene(meshes=[as_built.slab(), (v, np.asarray(ball.faces))])
    assert_both_views_give_the_rays_bits(scene, 256, (0.0, 0.3, 0.0))


def test_the_light_view_and_points_give_the_rays_bits():
    scene, light = scenes.bunny_floating()
    rays = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Exact(samples=256, engine="rays"))
    masks = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Exact(samples=256, engine="masks"))
    on = np.isfinite(rays.receiver_depth)
    assert ((rays.visibility > 0) & (rays.visibility < 1)).sum() > 100
    assert same_share(rays.visibility, masks.visibility, on) >= SAME
    pts, _ = rays.receiver_points()
    a, b = rays.sample(pts), masks.sample(pts)
    assert float((a == b).mean()) >= SAME


def test_a_disk_and_the_sun_give_the_rays_bits():
    scene, _, cam = as_built.SCENES["blocks_on_table"]((64, 48))
    disk = ss.DiskLight(center=(0.5, 3.0, 0.5), normal=(0.0, -1.0, 0.0), radius=0.6)
    sun = ss.DirectionalLight(direction=(0.3, -1.0, 0.2), up=(0, 0, 1), angular_size=(5.0, 5.0))
    for light in (disk, sun):
        rays = ss.render(scene, light, cam, method=ss.Exact(samples=256, engine="rays"))
        masks = ss.render(scene, light, cam, method=ss.Exact(samples=256, engine="masks"))
        seen = np.isfinite(rays.depth)
        assert ((rays.visibility > 0) & (rays.visibility < 1)).sum() > 20
        assert same_share(rays.visibility, masks.visibility, seen) >= SAME


def test_behind_a_probe_the_masks_give_the_rays_bits():
    # The default call's shape: a 16-ray probe, then the receivers it is
    # unsure of decided by either engine; the probe's answers are the same.
    scene, light, cam = as_built.SCENES["table_and_chairs"]((64, 48))
    rays = ss.render(scene, light, cam, method=ss.Exact(samples=256, probe=16, engine="rays"))
    masks = ss.render(scene, light, cam, method=ss.Exact(samples=256, probe=16, engine="masks"))
    assert masks.method.engine == "masks" and masks.method.probe == 16
    seen = np.isfinite(rays.depth)
    assert ((rays.visibility > 0) & (rays.visibility < 1)).sum() > 100
    assert same_share(rays.visibility, masks.visibility, seen) >= SAME
    # Where the probe was sure, both kept its 0 or 1; elsewhere the masks
    # are what they are without the probe.
    alone = ss.render(scene, light, cam, method=ss.Exact(samples=256, engine="masks"))
    partial = (masks.visibility > 0) & (masks.visibility < 1)
    np.testing.assert_array_equal(masks.visibility[partial], alone.visibility[partial])


def test_the_engine_resolves_by_samples_on_the_cpu():
    scene, light, cam = as_built.SCENES["blocks_on_table"]((32, 24))
    few = ss.render(scene, light, cam, method=ss.Exact(samples=64))
    default = ss.render(scene, light, cam, method=ss.Exact())
    many = ss.render(scene, light, cam, method=ss.Exact(samples=1024))
    probed = ss.render(scene, light, cam, method=ss.Exact(samples=1024, probe=16))
    assert few.method.engine == "rays"
    # From 256 samples in the eye view, `Exact()`'s own (MASKS_FROM); from
    # 1024 in the light view (MASKS_FROM_LIGHT_VIEW).
    assert default.method == ss.Exact(samples=256, engine="masks")
    maps = {n: ss.soft_shadow_map(scene, light, resolution=16, method=ss.Exact(samples=n)) for n in (256, 1024)}
    assert maps[256].method.engine == "rays" and maps[1024].method.engine == "masks"
    assert many.method.engine == "masks"
    # The probe's own rays aside, the receivers it is unsure of are decided
    # by the same rule.
    assert probed.method.engine == "masks"
    assert ss.render(scene, light, cam, method=ss.Exact(samples=64, probe=16)).method.engine == "rays"
    assert ss.Exact().engine is None
    assert ss.Exact(engine="masks") == ss.Exact(engine="masks") != ss.Exact(engine="rays")


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(engine="triangles"), r'^engine: must be one of \["rays", "masks"\], got "triangles"'),
    ],
)
def test_bad_engine(kwargs, words):
    with pytest.raises(ValueError, match=words):
        ss.Exact(**kwargs)


def test_an_engine_of_the_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="engine"):
        ss.Exact(engine=3)  # type: ignore[arg-type]


def test_the_gpu_refuses_the_masks():
    scene, light = scenes.square_plate(side=1.0, height=2.0)
    # Refused when the config resolves, before any adapter is asked for.
    with pytest.raises(ValueError, match="^engine: the GPU backend traces rays"):
        ss.soft_shadow_map(scene, light, resolution=16, method=ss.Exact(engine="masks"), backend="gpu")


def test_a_point_light_runs_the_rays_under_either_engine():
    # Every sample of a point light's pattern lies at its centre: the masks
    # have no cells to sort them into and the rays answer (no endless split).
    scene, light = scenes.square_plate(side=1.0, height=2.0)
    point = ss.RectLight(center=light.center, normal=light.normal, up=light.up, size=(0.0, 0.0))
    a = ss.soft_shadow_map(scene, point, resolution=32, method=ss.Exact(samples=1024, engine="masks"))
    b = ss.soft_shadow_map(scene, point, resolution=32, method=ss.Exact(samples=1024, engine="rays"))
    np.testing.assert_array_equal(a.visibility, b.visibility)
    assert set(np.unique(a.visibility)) <= {0.0, 1.0} and (a.visibility == 0).any()
