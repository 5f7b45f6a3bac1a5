"""Bad input raises ValueError/TypeError naming the argument; nothing panics."""

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes


@pytest.fixture(scope="module")
def plate():
    return scenes.square_plate()


def good_depth(n=8):
    occ = np.full((n, n), np.inf, np.float32)
    occ[2:5, 2:5] = 2.0
    return occ, np.full((n, n), 4.0, np.float32)


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(resolution=0), ValueError, "resolution"),
        (dict(resolution=-3), ValueError, "resolution"),
        (dict(resolution=(16, 0)), ValueError, "resolution"),
        (dict(resolution=(16, 16, 2)), ValueError, "resolution"),
        (dict(resolution=2.5), TypeError, "resolution"),
        (dict(resolution=True), TypeError, "resolution"),
        (dict(resolution=1 << 20), ValueError, "resolution.*bytes"),
        (dict(extent=(0.0, 1.0)), ValueError, "extent"),
        (dict(extent=(-1.0, 1.0)), ValueError, "extent"),
        (dict(extent=(np.inf, 1.0)), ValueError, "extent"),
        (dict(extent=(np.nan, 1.0)), ValueError, "extent"),
        (dict(extent="wide"), TypeError, "extent"),
        (dict(passes=9), ValueError, "passes"),
        (dict(passes=0), ValueError, "passes"),
        (dict(passes=1.0), TypeError, "passes"),
        (dict(method="bogus"), ValueError, "method"),
        (dict(backend="tpu"), ValueError, "backend"),
        (dict(backend=3), TypeError, "backend"),
    ],
)
def test_bad_options(plate, kwargs, exc, words):
    scene, light = plate
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map(scene, light, **kwargs)


def test_bad_scene_and_light_types(plate):
    scene, light = plate
    with pytest.raises(TypeError, match="scene"):
        ss.soft_shadow_map("scene", light)
    with pytest.raises(TypeError, match="light"):
        ss.soft_shadow_map(scene, (0, 4, 0))


@pytest.mark.parametrize(
    "occluders, receivers, exc, words",
    [
        ([], [scenes.floor()], ValueError, "occluders.*no occluder"),
        ([scenes.quad((0, 2, 0), 0.5)], [], ValueError, "receivers.*no receiver"),
        ([], [], ValueError, "occluders"),
        (
            [(np.array([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])],
            [scenes.floor()],
            ValueError,
            r"occluders\[0\].*vertex 0",
        ),
        ([(np.zeros((3, 3)), [[0, 1, 3]])], [scenes.floor()], ValueError, r"occluders\[0\].*indices"),
        ([(np.zeros((3, 3)), [[0, 1, -1]])], [scenes.floor()], ValueError, r"occluders\[0\].*indices"),
        ([(np.zeros((3, 2)), [[0, 1, 2]])], [scenes.floor()], ValueError, r"occluders\[0\].*vertices"),
        ([(np.zeros((3, 3)), [[0, 1]])], [scenes.floor()], ValueError, r"occluders\[0\].*faces"),
        ([(np.zeros((3, 3)), np.array([[0.0, 1.0, 2.0]]))], [scenes.floor()], TypeError, r"occluders\[0\].*integers"),
        ([scenes.quad((0, 2, 0), 0.5)], ["floor"], TypeError, r"receivers\[0\]"),
        (42, [scenes.floor()], TypeError, "occluders"),
    ],
)
def test_bad_scenes(occluders, receivers, exc, words):
    with pytest.raises(exc, match=words):
        ss.Scene(occluders=occluders, receivers=receivers)


def test_occluders_behind_the_light_need_an_explicit_extent():
    scene = ss.Scene(occluders=[scenes.quad((0, 5, 0), 0.5)], receivers=[scenes.floor()])
    light = scenes.default_light()
    with pytest.raises(ValueError, match="occluders.*extent"):
        ss.soft_shadow_map(scene, light)
    # With an explicit extent the part behind the light is clipped: no shadow.
    sm = ss.soft_shadow_map(scene, light, extent=0.5, resolution=16)
    assert np.all(sm.visibility == 1.0)


@pytest.mark.parametrize(
    "change, exc, words",
    [
        (lambda o, r: (np.ones(o.shape, np.int32), r), TypeError, "occluder_depth.*float"),
        (lambda o, r: (o, r.tolist()), TypeError, "receiver_depth.*numpy"),
        (lambda o, r: (o[None], r), ValueError, "occluder_depth.*2-D"),
        (lambda o, r: (o, r[:, :0]), ValueError, "receiver_depth.*empty"),
        (lambda o, r: (np.where(o == 2.0, np.nan, o).astype(np.float32), r), ValueError, "occluder_depth.*NaN"),
        (lambda o, r: (o, np.where(r == 4.0, -4.0, r).astype(np.float32)), ValueError, "receiver_depth.*> 0"),
        (lambda o, r: (np.where(o == 2.0, 0.0, o).astype(np.float32), r), ValueError, "occluder_depth.*> 0"),
        (lambda o, r: (np.where(o == 2.0, -np.inf, o).astype(np.float32), r), ValueError, "occluder_depth.*> 0"),
    ],
)
def test_bad_depth_maps(change, exc, words):
    occ, rec = change(*good_depth())
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map_from_depth(occ, rec, light_size=(1, 1), extent=(0.5, 0.5))


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(light_size=(0, 1)), ValueError, "light_size"),
        (dict(light_size=(1, -1)), ValueError, "light_size"),
        (dict(light_size=(1, np.nan)), ValueError, "light_size"),
        (dict(extent=(0.5, 0)), ValueError, "extent"),
        (dict(extent=(0.5, np.inf)), ValueError, "extent"),
        (dict(occluder_depth_back=np.ones((3, 3), np.float32)), ValueError, "occluder_depth_back.*shape"),
    ],
)
def test_bad_depth_options(kwargs, exc, words):
    occ, rec = good_depth()
    args = dict(light_size=(1, 1), extent=(0.5, 0.5))
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map_from_depth(occ, rec, **args)


def test_float64_and_strided_depth_maps_are_accepted():
    occ, rec = good_depth(16)
    a = ss.soft_shadow_map_from_depth(occ, rec, light_size=1, extent=0.5).visibility
    big = np.full((16, 32), 4.0)
    big[:, ::2] = rec
    b = ss.soft_shadow_map_from_depth(occ.astype(np.float64), big[:, ::2], light_size=1, extent=0.5).visibility
    np.testing.assert_array_equal(a, b)


def test_the_core_refuses_bad_values_even_past_the_python_checks():
    # The bindings are the last line: values reaching them unchecked still
    # come back as ValueError naming the argument, never a panic.
    from softshadow import _core

    occ, rec = good_depth()
    occ[0, 0] = np.nan
    with pytest.raises(ValueError, match="occluder_depth"):
        _core.shadow_map_from_depth(occ, None, rec, (1.0, 1.0), (0.5, 0.5), "ssm")
    v = np.zeros((3, 3))
    with pytest.raises(ValueError, match="occluders.*face 0"):
        _core.shadow_map_from_meshes(
            v,
            np.array([[0, 1, 7]], np.uint32),
            v,
            np.array([[0, 1, 2]], np.uint32),
            ((0, 4, 0), (0, -1, 0), (0, 0, 1), (1, 1)),
            (8, 8),
            (0.5, 0.5),
            "ssm",
            passes=1,
        )
    with pytest.raises(ValueError, match="resolution"):
        _core.shadow_map_from_meshes(
            v,
            np.array([[0, 1, 2]], np.uint32),
            v,
            np.array([[0, 1, 2]], np.uint32),
            ((0, 4, 0), (0, -1, 0), (0, 0, 1), (1, 1)),
            (1 << 20, 1 << 20),
            None,
            "ssm",
            passes=1,
        )
    with pytest.raises(ValueError, match="up"):
        _core.light_frame(((0, 0, 0), (0, 0, 1), (0, 0, 2), (1, 1)))
    with pytest.raises(ValueError, match="C-contiguous"):
        _core.shadow_map_from_depth(
            good_depth()[0][:, ::2], None, good_depth()[1][:, ::2], (1.0, 1.0), (0.5, 0.5), "ssm"
        )


def test_the_core_checks_shapes_not_just_sizes():
    from softshadow import _core

    occ = np.full((8, 16), 2.0, np.float32)
    rec = np.full((16, 8), 4.0, np.float32)
    with pytest.raises(ValueError, match="occluder_depth_back.*shape"):
        _core.shadow_map_from_depth(occ, np.ascontiguousarray(occ.T), rec, (1.0, 1.0), (0.5, 0.5), "ssm")
    light = ((0, 4, 0), (0, -1, 0), (0, 0, 1), (1, 1))
    with pytest.raises(ValueError, match="occluder_depth_back.*shape"):
        _core.sample_points(
            light, (0.5, 0.5), (8, 16), np.zeros((1, 3)), ss.Ssm(), occluder_depth=rec, occluder_depth_back=occ
        )
    with pytest.raises(ValueError, match="occluders: pass either"):
        _core.sample_points(light, (0.5, 0.5), (8, 16), np.zeros((1, 3)), ss.Ssm())
