"""Bad input at every public entry point: each case raises ValueError,
TypeError or MemoryError (TooLargeError is both a ValueError and a
MemoryError) whose message starts with the argument's name -- for the
extension's own functions, pyo3's conversion errors name it in a note
("while processing 'occluder_depth'"). Nothing panics: after every case a
good call still works (the autouse fixture).
"""

import numpy as np
import pytest
from hard_cases.common import METHODS, has_option

import softshadow as ss
from softshadow import _core, io, scenes


def _good_depth(n=8):
    occ = np.full((n, n), np.inf, np.float32)
    occ[2:5, 2:5] = 2.0
    return occ, np.full((n, n), 4.0, np.float32)


@pytest.fixture(autouse=True)
def still_works_afterwards():
    yield
    occ, rec = _good_depth()
    v = ss.soft_shadow_map_from_depth(occ, rec, light_size=1.0, extent=0.5).visibility
    assert v.min() < 0.5 and v.max() == 1.0
    scene, light = scenes.square_plate()
    assert ss.soft_shadow_map(scene, light, resolution=8, method="exact", samples=4).visibility.min() == 0.0


@pytest.fixture(scope="module")
def plate():
    return scenes.square_plate()


LIGHT = ((0.0, 4.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0))


# --------------------------------------------------------------------------
# The light view's options and the memory they would need
# --------------------------------------------------------------------------


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
    "kwargs, exc, words",
    [
        (dict(samples=0), ValueError, "samples"),
        (dict(samples=-16), ValueError, "samples"),
        (dict(samples=24), ValueError, "samples.*16, 64, 256, 1024"),  # bitmask's counts
        (dict(samples=16.0), TypeError, "samples"),
        (dict(samples=True), TypeError, "samples"),
        (dict(method=None), TypeError, "method"),
        (dict(passes=True), TypeError, "passes"),
        (dict(extent=(2e6, 1.0)), ValueError, "extent"),
        (dict(occluder_resolution=(8, -1)), ValueError, "occluder_resolution"),
    ],
)
def test_bad_options_for_the_sampling_methods(kwargs, exc, words):
    scene, light = scenes.square_plate()
    kw = dict(method="bitmask", resolution=8)
    kw.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map(scene, light, **kw)


def test_absurd_resolutions_are_refused_before_allocating_as_memory_errors():
    scene, light = scenes.square_plate()
    for kw in (dict(resolution=(1 << 15, 1 << 14)), dict(occluder_resolution=1 << 20)):
        with pytest.raises(MemoryError, match=r"resolution: .* would need \d+ bytes") as e:
            ss.soft_shadow_map(scene, light, **kw)
        assert isinstance(e.value, ValueError) and isinstance(e.value, ss.TooLargeError)
    # The core refuses it too, by the same type, before touching the meshes.
    v, f = scene.occluder_mesh
    with pytest.raises(ss.TooLargeError, match="resolution.*bytes"):
        _core.shadow_map_from_meshes(v, f, v, f, LIGHT, (1 << 20, 1 << 20), None, "ssm", passes=1)


def test_maps_larger_than_the_memory_available_are_refused_before_allocating(monkeypatch):
    # Rust aborts the process when an allocation fails, so the core adds up
    # its maps' bytes first and compares them with MemAvailable, or with the
    # cap SOFTSHADOW_MEMORY_LIMIT (set small here to stand for a small machine).
    scene, light = scenes.square_plate()
    monkeypatch.setenv("SOFTSHADOW_MEMORY_LIMIT", "100000")
    assert ss.soft_shadow_map(scene, light, resolution=32).visibility.shape == (32, 32)
    with pytest.raises(ss.TooLargeError, match=r"resolution: 1024x1024 .* 41943040 bytes .* 100000 bytes"):
        ss.soft_shadow_map(scene, light, resolution=1024)
    occ = np.full((1024, 1024), np.inf, np.float32)
    with pytest.raises(MemoryError, match="receiver_depth: 1024x1024 maps would need"):
        ss.soft_shadow_map_from_depth(occ, occ, light_size=1.0, extent=0.5)
    monkeypatch.delenv("SOFTSHADOW_MEMORY_LIMIT")
    assert ss.soft_shadow_map(scene, light, resolution=1024, method="exact", samples=1).visibility.min() == 0.0


def test_an_eye_view_too_large_for_the_memory_is_refused_before_allocating(monkeypatch):
    # The traced eye view (the default call) adds up its triangles', tree's
    # and images' bytes first (src/eye/budget.rs) and names the meshes.
    scene = ss.Scene(meshes=[scenes.quad((0.0, 0.0, 0.0), 2.0), scenes.quad((0.0, 1.0, 0.0), 0.5)])
    light = ss.RectLight(center=(0, 3, 0), normal=(0, -1, 0), up=(0, 0, 1), size=(1.0, 1.0))
    cam = ss.Camera.look_at(eye=(2, 2, 2), target=(0, 0, 0), up=(0, 1, 0), fov_y=40.0, resolution=(64, 48))
    monkeypatch.setenv("SOFTSHADOW_MEMORY_LIMIT", "100000")
    refused = r"meshes: 4 triangles traced at 64x48 pixels would need about \d+ bytes"
    with pytest.raises(ss.TooLargeError, match=refused):
        ss.render(scene, light, cam)
    assert scene.prepared.held == (False, 0)  # refused before the triangles were gathered
    monkeypatch.setenv("SOFTSHADOW_MEMORY_LIMIT", "10000000")
    assert ss.render(scene, light, cam).visibility.shape == (48, 64)


def test_the_memory_check_counts_what_closed_gaps_keep_per_layer(monkeypatch):
    # Connected micro-quads keep 8 more f32 per occluder texel and layer
    # (corner depths and their reciprocals): 64² maps with the hierarchy,
    # two layers, need 196608 bytes with open gaps and 557056 with closed.
    scene, light = scenes.square_plate()
    monkeypatch.setenv("SOFTSHADOW_MEMORY_LIMIT", "300000")
    open_gaps = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Bitmask(gaps="open"))
    assert open_gaps.visibility.min() == 0.0
    with pytest.raises(ss.TooLargeError, match=r"^resolution: 64x64 .* 557056 bytes"):
        ss.soft_shadow_map(scene, light, resolution=64, method=ss.Bitmask())


# --------------------------------------------------------------------------
# Scenes, meshes and lights
# --------------------------------------------------------------------------


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


@pytest.mark.parametrize(
    "mesh, exc, words",
    [
        ((np.array([[0, 0, np.inf], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]]), ValueError, r"occluders\[0\].*vertex 0"),
        ((np.zeros((3, 3), bool), [[0, 1, 2]]), TypeError, r"occluders\[0\].*vertices"),
        ((np.zeros((3, 3)).astype(object), [[0, 1, 2]]), TypeError, r"occluders\[0\].*vertices"),
        ((np.zeros((3, 3)), np.array([[0, 1, 2**32]], np.int64)), ValueError, r"occluders\[0\].*indices"),
        ((np.zeros((3, 3)), np.zeros((1, 3, 1), np.int32)), ValueError, r"occluders\[0\].*faces"),
    ],
)
def test_bad_meshes(mesh, exc, words):
    with pytest.raises(exc, match=words):
        ss.Scene(occluders=[mesh], receivers=[scenes.floor()])


def test_degenerate_open_and_non_manifold_meshes_are_accepted():
    # Degenerate triangles (repeated or collinear vertices) cover no texel and
    # hit no ray; open meshes (a plate) and non-manifold ones (three
    # triangles on one edge, duplicated faces) are surfaces like any other:
    # the occluder maps and the ray caster need no volume.
    plate_v, plate_f = scenes.quad((0.0, 2.0, 0.0), 0.5)
    degenerate = np.array([[0, 0, 1], [1, 1, 1], [2, 3, 2]], np.uint32)
    collinear_v = np.array([[-0.5, 2.0, 0.0], [0.0, 2.0, 0.0], [0.5, 2.0, 0.0]])
    # A vertical fin on the plate's middle line: three faces share an edge.
    fin_v = np.array([[-0.5, 2.0, 0.0], [0.5, 2.0, 0.0], [0.0, 2.5, 0.0]])
    light = scenes.default_light()
    for method in METHODS:
        kw = dict(resolution=32, extent=0.5, method=method)
        if has_option(method, "samples"):
            kw["samples"] = 64
        base = ss.soft_shadow_map(ss.Scene(occluders=[(plate_v, plate_f)], receivers=[scenes.floor()]), light, **kw)
        only_degenerate = ss.Scene(
            occluders=[(collinear_v, [[0, 1, 2]]), (plate_v, degenerate)], receivers=[scenes.floor()]
        )
        np.testing.assert_array_equal(ss.soft_shadow_map(only_degenerate, light, **kw).visibility, 1.0)
        messy = ss.Scene(
            occluders=[
                (plate_v, np.vstack([plate_f, plate_f, degenerate, plate_f[:, ::-1]])),
                (collinear_v, [[0, 1, 2]]),
            ],
            receivers=[scenes.floor()],
        )
        np.testing.assert_array_equal(ss.soft_shadow_map(messy, light, **kw).visibility, base.visibility)
        fin = ss.Scene(occluders=[(plate_v, plate_f), (fin_v, [[0, 1, 2]])], receivers=[scenes.floor()])
        v = ss.soft_shadow_map(fin, light, **kw).visibility
        assert np.isfinite(v).all() and np.all(v <= base.visibility + 1e-6)


def test_occluders_behind_the_light_need_an_explicit_extent():
    scene = ss.Scene(occluders=[scenes.quad((0, 5, 0), 0.5)], receivers=[scenes.floor()])
    light = scenes.default_light()
    with pytest.raises(ValueError, match="occluders.*extent"):
        ss.soft_shadow_map(scene, light)
    # With an explicit extent the part behind the light is clipped: no shadow.
    sm = ss.soft_shadow_map(scene, light, extent=0.5, resolution=16)
    assert np.all(sm.visibility == 1.0)


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(center=(0, 0)), ValueError, "center"),
        (dict(center="origin"), TypeError, "center"),
        (dict(center=(0, np.inf, 0)), ValueError, "center"),
        (dict(normal=(0, 0, 0)), ValueError, "normal.*zero"),
        (dict(up=(0, 0, 0)), ValueError, "up.*zero"),
        (dict(up=(0, 1, 0)), ValueError, "up.*parallel"),  # anti-parallel to normal
        (dict(up=(1e-9, 1, 0)), ValueError, "up.*parallel"),  # within 1e-6 rad
        (dict(size=-1.0), ValueError, "size"),
        (dict(size=(1.0, np.inf)), ValueError, "size"),
        (dict(size=(1.0, np.nan)), ValueError, "size"),
        (dict(size=(1.0, 2.0, 3.0)), ValueError, "size"),
    ],
)
def test_bad_lights(kwargs, exc, words):
    args = dict(center=(0, 4, 0), normal=(0, -1, 0), up=(0, 0, 1), size=1.0)
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.RectLight(**args)


def test_up_nearly_but_not_parallel_is_accepted():
    light = ss.RectLight(center=(0, 4, 0), normal=(0, -1, 0), up=(1e-3, 1, 0), size=1.0)
    np.testing.assert_allclose(light.v, (1, 0, 0), atol=1e-12)


# --------------------------------------------------------------------------
# Depth maps (soft_shadow_map_from_depth)
# --------------------------------------------------------------------------


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
    occ, rec = change(*_good_depth())
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
    occ, rec = _good_depth()
    args = dict(light_size=(1, 1), extent=(0.5, 0.5))
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map_from_depth(occ, rec, **args)


@pytest.mark.parametrize(
    "kwargs, exc, words",
    [
        (dict(light_size=(1.0, 1.0, 1.0)), ValueError, "light_size"),
        (dict(light_size="big"), TypeError, "light_size"),
        (dict(light_size=(1.0, np.inf)), ValueError, "light_size"),
        (dict(method="exact"), ValueError, "method.*triangles"),
        (dict(samples=64), ValueError, "samples.*ssm"),
    ],
)
def test_bad_depth_entry_options(kwargs, exc, words):
    occ, rec = _good_depth()
    args = dict(light_size=1.0, extent=0.5)
    args.update(kwargs)
    with pytest.raises(exc, match=words):
        ss.soft_shadow_map_from_depth(occ, rec, **args)


def test_complex_depth_maps_are_refused():
    occ, rec = _good_depth()
    with pytest.raises(TypeError, match="occluder_depth.*float"):
        ss.soft_shadow_map_from_depth(occ.astype(np.complex64), rec, light_size=1.0, extent=0.5)


def test_float64_and_strided_depth_maps_are_accepted():
    occ, rec = _good_depth(16)
    a = ss.soft_shadow_map_from_depth(occ, rec, light_size=1, extent=0.5).visibility
    big = np.full((16, 32), 4.0)
    big[:, ::2] = rec
    b = ss.soft_shadow_map_from_depth(occ.astype(np.float64), big[:, ::2], light_size=1, extent=0.5).visibility
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    "make",
    [
        lambda a: np.asfortranarray(a),
        lambda a: a[::-1, ::-1].copy()[::-1, ::-1],  # negative strides
        lambda a: a.astype(">f4"),  # big-endian
        lambda a: a.astype(np.float16),
        lambda a: np.lib.stride_tricks.as_strided(a, a.shape, a.strides, writeable=False),
    ],
)
def test_depth_maps_in_any_float_layout_are_accepted(make):
    occ, rec = _good_depth()
    want = ss.soft_shadow_map_from_depth(occ, rec, light_size=1.0, extent=0.5).visibility
    got = ss.soft_shadow_map_from_depth(make(occ), make(rec), light_size=1.0, extent=0.5).visibility
    np.testing.assert_array_equal(got, want)


# --------------------------------------------------------------------------
# Points (ShadowMap.sample)
# --------------------------------------------------------------------------


def test_bad_points_and_outside_values():
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=16)
    with pytest.raises(TypeError, match="points"):
        sm.sample([["a", "b", "c"]])
    with pytest.raises(TypeError, match="points"):
        sm.sample(np.zeros((2, 3), complex))
    with pytest.raises(TypeError, match="outside"):
        sm.sample(np.zeros((2, 3)), outside="lit")
    # Empty, integer and behind-the-light points are fine.
    assert sm.sample(np.zeros((0, 3))).shape == (0,)
    np.testing.assert_array_equal(sm.sample(np.array([[0, 9, 0], [0, 4, 0]])), 1.0)
    assert np.isnan(sm.sample([[0.0, 9.0, 0.0]], outside=np.nan)).all()


# --------------------------------------------------------------------------
# The core's own functions: the last line behind the Python checks
# --------------------------------------------------------------------------


def test_the_core_refuses_bad_values_even_past_the_python_checks():
    # The bindings are the last line: values reaching them unchecked still
    # come back as ValueError naming the argument, never a panic.
    occ, rec = _good_depth()
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
            _good_depth()[0][:, ::2], None, _good_depth()[1][:, ::2], (1.0, 1.0), (0.5, 0.5), "ssm"
        )


def test_the_core_checks_shapes_not_just_sizes():
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


@pytest.mark.parametrize(
    "call, exc, words",
    [
        # Wrong dtypes and shapes: pyo3 names the argument in a note.
        (
            lambda o, r: _core.shadow_map_from_depth(o.astype(np.float64), None, r, (1, 1), (0.5, 0.5), "ssm"),
            TypeError,
            "while processing 'occluder_depth'",
        ),
        (
            lambda o, r: _core.shadow_map_from_depth(o, None, r[None], (1, 1), (0.5, 0.5), "ssm"),
            TypeError,
            "while processing 'receiver_depth'",
        ),
        (
            lambda o, r: _core.shadow_map_from_depth(o, None, r, (1, 1, 1), (0.5, 0.5), "ssm"),
            ValueError,
            "while processing 'light_size'",
        ),
        # A light is a rectangle's 4-tuple or a sun's 3-tuple: neither fits.
        (lambda o, r: _core.light_frame((1, 2)), TypeError, "while processing 'light'"),
        # Values: the core's messages start with the name.
        (
            lambda o, r: _core.shadow_map_from_depth(o, None, r, (1, 1), (0.5, 0.5), "bitmask", samples=-1),
            ValueError,
            "samples",
        ),
        (
            lambda o, r: _core.shadow_map_from_depth(o, None, r, (1e-40, 1), (0.5, 0.5), "bitmask"),
            ValueError,
            "light_size",
        ),
        (
            lambda o, r: _core.sample_points(LIGHT, (0.5, 0.5), (-8, 8), np.zeros((1, 3)), ss.Ssm(), occluder_depth=o),
            ValueError,
            "resolution",
        ),
        (
            lambda o, r: _core.sample_points(
                LIGHT,
                (0.5, 0.5),
                (8, 8),
                np.zeros((1, 3)),
                ss.Ssm(),
                occluder_depth=np.full((8, 8), np.nan, np.float32),
            ),
            ValueError,
            "occluder layer 0.*> 0",
        ),
        (lambda o, r: _core.receiver_points(-r, LIGHT, (0.5, 0.5)), ValueError, "receiver_depth.*> 0"),
        (
            lambda o, r: _core.shadow_map_from_meshes(
                np.zeros((3, 3)),
                np.array([[0, 1, 2]], np.uint32),
                np.zeros((3, 3)),
                np.array([[0, 1, 2]], np.uint32),
                LIGHT,
                (8, 8),
                None,
                "ssm",
                passes=-2,
            ),
            ValueError,
            "passes",
        ),
    ],
)
def test_core_functions_name_the_argument(call, exc, words):
    occ, rec = _good_depth()
    with pytest.raises(exc) as e:
        call(occ, rec)
    text = str(e.value) + " ".join(getattr(e.value, "__notes__", []))
    assert pytest.importorskip("re").search(words, text), text


# --------------------------------------------------------------------------
# Files (softshadow.io)
# --------------------------------------------------------------------------


def test_io_errors_name_the_path_or_channel(tmp_path):
    pytest.importorskip("OpenEXR")
    with pytest.raises(ValueError, match="channels\\['V'\\].*2-D"):
        io.write_exr(tmp_path / "a.exr", {"V": np.zeros((2, 2, 2))})
    with pytest.raises(ValueError, match="channels.*one shape"):
        io.write_exr(tmp_path / "a.exr", {"V": np.zeros((2, 2)), "W": np.zeros((3, 2))})
    with pytest.raises(FileNotFoundError, match="path: .*missing.exr"):
        io.read_exr(tmp_path / "missing.exr")
    (tmp_path / "text.exr").write_text("not an image")
    with pytest.raises(ValueError, match="path: .*text.exr"):
        io.read_exr(tmp_path / "text.exr")
    with pytest.raises(FileNotFoundError, match="path: .*no_dir"):
        io.write_exr(tmp_path / "no_dir" / "a.exr", np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"compression: must be one of \['none', 'zip', 'zstd'\], got 'lzw'"):
        io.write_exr(tmp_path / "a.exr", np.zeros((2, 2)), compression="lzw")
    assert not (tmp_path / "a.exr").exists()


def test_too_large_error_is_the_core_s_and_both_a_value_and_a_memory_error():
    # Defined by the core (with two bases, made when _core is imported), so
    # the core raises the class the package exports, without importing it.
    assert ss.TooLargeError is _core.TooLargeError
    assert issubclass(ss.TooLargeError, ValueError) and issubclass(ss.TooLargeError, MemoryError)
    assert ss.TooLargeError.__module__ == "softshadow._core"
