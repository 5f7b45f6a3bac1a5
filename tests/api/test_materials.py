"""The colours users' files carry, read by ``Scene.from_trimesh`` into one
:class:`softshadow.Material` per mesh: vertex and face colours (sRGB-decoded),
glTF ``baseColorFactor`` and OBJ ``Kd`` (linear), base-colour textures with
their UVs; through glb and OBJ files written and loaded again."""

from __future__ import annotations

import json
import pickle
import struct

import numpy as np
import pytest

import softshadow as ss
from softshadow.materials import Material, srgb_to_linear

trimesh = pytest.importorskip("trimesh")
Image = pytest.importorskip("PIL.Image")
PBRMaterial = trimesh.visual.material.PBRMaterial


def exact_srgb(code: int) -> float:
    c = code / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def box():
    return trimesh.creation.box(extents=(1, 1, 1))


def only(scene: ss.Scene) -> Material:
    assert len(scene.materials) == 1
    (m,) = scene.materials
    assert isinstance(m, Material)
    return m


def glb_json_and_bin(path) -> tuple[dict, bytes]:
    """A .glb's JSON chunk and BIN chunk, read by hand."""
    data = path.read_bytes()
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    assert magic == b"glTF"
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON"
    tree = json.loads(data[20 : 20 + json_len])
    bin_len, bin_type = struct.unpack_from("<I4s", data, 20 + json_len)
    assert bin_type == b"BIN\x00"
    return tree, data[28 + json_len : 28 + json_len + bin_len]


def test_srgb_decoding_is_the_exact_transfer_function():
    codes = np.arange(256, dtype=np.uint8)
    lut = srgb_to_linear(codes)
    assert lut.dtype == np.float32
    np.testing.assert_array_equal(lut, np.array([exact_srgb(c) for c in range(256)], dtype=np.float32))
    assert lut[0] == 0.0 and lut[255] == 1.0
    assert lut[10] == np.float32(10 / 255 / 12.92)  # the linear segment (10/255 <= 0.04045)
    assert lut[11] == np.float32(((11 / 255 + 0.055) / 1.055) ** 2.4)  # the power segment
    assert abs(float(lut[128]) - 0.2158605) < 1e-7
    assert lut[128] == np.float32(0.21586050011389926)
    np.testing.assert_allclose(srgb_to_linear(codes / 255.0), lut, rtol=1e-6, atol=1e-9)
    with pytest.raises(TypeError, match="values"):
        srgb_to_linear(np.arange(3, dtype=np.int64))


def test_vertex_colours_are_decoded_per_vertex():
    mesh = box()
    rgba = np.zeros((len(mesh.vertices), 4), dtype=np.uint8)
    rgba[:, 0] = 128
    rgba[:, 1] = np.arange(len(mesh.vertices)) * 30
    rgba[:, 2] = 255
    rgba[:, 3] = 7  # alpha is dropped
    mesh.visual.vertex_colors = rgba
    scene = ss.Scene.from_trimesh(mesh)
    m = only(scene)
    assert m.kind == "vertex" and m.color == (1.0, 1.0, 1.0)
    assert m.vertex_colors.shape == (len(mesh.vertices), 3) and m.vertex_colors.dtype == np.float32
    np.testing.assert_array_equal(m.vertex_colors[:, 0], np.float32(exact_srgb(128)))
    np.testing.assert_array_equal(m.vertex_colors[:, 1], [np.float32(exact_srgb(30 * k)) for k in range(8)])
    np.testing.assert_array_equal(m.vertex_colors[:, 2], 1.0)
    assert m.face_colors is None and m.uv is None and m.texture is None
    kind, color, a1, a2 = m.to_core()
    assert (kind, color, a2) == ("vertex", (1.0, 1.0, 1.0), None)
    assert a1 is m.vertex_colors and a1.flags.c_contiguous and a1.dtype == np.float32


def test_face_colours_are_decoded_per_face():
    mesh = box()
    mesh.visual.face_colors = np.array([[128, 0, 255, 255]] * 6 + [[10, 64, 200, 255]] * 6, dtype=np.uint8)
    m = only(ss.Scene.from_trimesh(mesh))
    assert m.kind == "face" and m.face_colors.shape == (12, 3) and m.face_colors.dtype == np.float32
    np.testing.assert_array_equal(m.face_colors[0], np.float32([exact_srgb(128), 0.0, 1.0]))
    np.testing.assert_array_equal(m.face_colors[11], np.float32([exact_srgb(10), exact_srgb(64), exact_srgb(200)]))
    kind, color, a1, a2 = m.to_core()
    assert kind == "face" and a1.shape == (12, 3) and a2 is None


def test_no_colour_gives_none():
    plain = box()
    _ = plain.visual.face_colors  # reading trimesh's default grey does not make it a colour
    assert ss.Scene.from_trimesh(plain).materials == (None,)
    arrays = ss.Scene(meshes=[(plain.vertices, plain.faces), plain, (plain.vertices, plain.faces)])
    assert arrays.materials == (None, None, None)
    split = ss.Scene(occluders=[plain], receivers=[plain, plain])
    assert split.materials == (None,) * len(split.meshes) == (None,) * 3
    # A coloured trimesh passed to the constructor: geometry only, as before.
    coloured = box()
    coloured.visual.face_colors = [255, 0, 0, 255]
    assert ss.Scene(meshes=[coloured]).materials == (None,)
    assert repr(ss.Scene.from_trimesh(coloured)) == repr(ss.Scene(meshes=[coloured]))


def test_gltf_base_color_factor_round_trips_through_glb(tmp_path):
    mesh = box()
    factor = (0.5, 0.2, 0.9, 1.0)
    mesh.visual = trimesh.visual.TextureVisuals(material=PBRMaterial(baseColorFactor=factor))
    path = tmp_path / "factor.glb"
    mesh.export(path)
    tree, _ = glb_json_and_bin(path)
    (written,) = tree["materials"]
    # trimesh holds the factor as uint8: the file gets round(255 f) / 255, linear.
    np.testing.assert_allclose(
        written["pbrMetallicRoughness"]["baseColorFactor"][:3], np.round(np.multiply(factor[:3], 255)) / 255, rtol=1e-6
    )

    loaded = trimesh.load(path)
    (geom,) = loaded.geometry.values()
    assert geom.visual.material.baseColorFactor.dtype == np.uint8
    m = only(ss.Scene.from_trimesh(loaded))
    assert m.kind == "constant" and m.vertex_colors is None and m.texture is None
    np.testing.assert_array_equal(m.color, np.float32(np.round(np.multiply(factor[:3], 255)) / 255))
    np.testing.assert_allclose(m.color, factor[:3], atol=0.5 / 255)
    assert m.to_core() == ("constant", m.color, None, None)
    assert ss.Scene.from_trimesh(path).materials == (m,)  # from the path too

    # A float factor set by hand is kept as is; a material without one is white (glTF's default).
    mesh.visual.material._data["baseColorFactor"] = np.array([0.3, 0.6, 0.25, 1.0])
    np.testing.assert_array_equal(only(ss.Scene.from_trimesh(mesh)).color, np.float32([0.3, 0.6, 0.25]))
    mesh.visual = trimesh.visual.TextureVisuals(material=PBRMaterial())
    assert only(ss.Scene.from_trimesh(mesh)) == Material("constant", color=(1, 1, 1))


def textured_box(image, factor=None):
    mesh = box()
    uv = np.random.default_rng(1).random((len(mesh.vertices), 2))
    material = PBRMaterial(baseColorTexture=image, baseColorFactor=factor)
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    return mesh, uv


def test_gltf_texture_round_trips_through_glb_with_v_up(tmp_path):
    # Row 0 (the image's top) red, row 2 (its bottom) blue.
    pixels = np.zeros((3, 4, 3), dtype=np.uint8)
    pixels[0] = (255, 0, 0)
    pixels[1] = (0, 255, 0)
    pixels[2] = (0, 0, 255)
    pixels[:, 3] = (17, 128, 240)
    mesh, uv = textured_box(Image.fromarray(pixels), factor=(1.0, 0.5, 0.25, 1.0))
    path = tmp_path / "tex.glb"
    mesh.export(path)

    # The file holds glTF's v-down TEXCOORD_0: trimesh flipped it on export.
    tree, binary = glb_json_and_bin(path)
    accessor = tree["accessors"][tree["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]]
    view = tree["bufferViews"][accessor["bufferView"]]
    assert "byteStride" not in view or view["byteStride"] == 8
    offset = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    in_file = np.frombuffer(binary, dtype="<f4", count=2 * accessor["count"], offset=offset).reshape(-1, 2)

    loaded = trimesh.load(path)
    (geom,) = loaded.geometry.values()
    assert len(geom.vertices) == len(mesh.vertices)
    m = only(ss.Scene.from_trimesh(loaded))
    assert m.kind == "texture"
    assert m.uv.shape == (len(geom.vertices), 2) and m.uv.dtype == np.float32
    np.testing.assert_array_equal(m.uv, np.asarray(geom.visual.uv, dtype=np.float32))
    np.testing.assert_allclose(m.uv, uv, atol=1e-6)  # the round trip gives back the uv set
    np.testing.assert_allclose(m.uv[:, 0], in_file[:, 0], atol=1e-7)
    np.testing.assert_allclose(m.uv[:, 1], 1.0 - in_file[:, 1], atol=1e-6)  # trimesh's v = 1 - glTF's
    assert m.texture.shape == (3, 4, 3) and m.texture.dtype == np.uint8
    np.testing.assert_array_equal(m.texture, pixels)  # encoded sRGB, untouched
    np.testing.assert_array_equal(m.color, np.float32([1.0, 128 / 255, 64 / 255]))

    # The convention the sampler reads, row = (1 - v) * H: v near 1 is row 0,
    # as trimesh's own lookup says.
    probe = np.array([[0.1, 0.99], [0.1, 0.5], [0.1, 0.01]])
    rows = np.floor((1 - probe[:, 1]) * 3).astype(int)
    np.testing.assert_array_equal(rows, [0, 1, 2])
    looked_up = trimesh.visual.color.uv_to_color(probe, Image.fromarray(pixels))[:, :3]
    np.testing.assert_array_equal(looked_up, pixels[rows, 0])

    kind, color, a1, a2 = m.to_core()
    assert kind == "texture" and color == m.color
    assert a1 is m.uv and a2 is m.texture and a1.flags.c_contiguous and a2.flags.c_contiguous

    # No factor: 1.
    plain, _ = textured_box(Image.fromarray(pixels))
    plain.export(tmp_path / "plain.glb")
    assert only(ss.Scene.from_trimesh(tmp_path / "plain.glb")).color == (1.0, 1.0, 1.0)


@pytest.mark.parametrize("mode", ["RGBA", "L", "P", "LA", "I;16"])
def test_texture_images_of_any_mode_become_rgb8(mode):
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3) * 12
    if mode == "I;16":
        grey = (np.arange(6, dtype=np.uint16).reshape(2, 3) * 10000).astype(np.uint16)
        image = Image.fromarray(grey)
        assert image.mode == "I;16"
        want = np.repeat((grey >> 8).astype(np.uint8)[:, :, None], 3, axis=2)
    else:
        image = Image.fromarray(rgb).convert(mode)
        want = np.asarray(image.convert("RGB"))
    mesh, _ = textured_box(image)
    m = only(ss.Scene.from_trimesh(mesh))
    assert m.kind == "texture" and m.texture.shape == (2, 3, 3) and m.texture.dtype == np.uint8
    np.testing.assert_array_equal(m.texture, want)
    if mode == "RGBA":
        np.testing.assert_array_equal(m.texture, rgb)  # alpha dropped, colours untouched


def test_texture_without_uv_or_image_falls_back_to_the_factor():
    mesh = box()
    image = Image.new("RGB", (2, 2), (200, 10, 10))
    mesh.visual = trimesh.visual.TextureVisuals(
        material=PBRMaterial(baseColorTexture=image, baseColorFactor=(0.2, 0.4, 0.6))
    )
    assert only(ss.Scene.from_trimesh(mesh)) == Material("constant", color=np.float32([51, 102, 153]) / 255)
    mesh.visual = trimesh.visual.TextureVisuals(
        uv=np.zeros((8, 2)), material=PBRMaterial(baseColorFactor=(0.2, 0.4, 0.6))
    )
    assert only(ss.Scene.from_trimesh(mesh)).kind == "constant"
    # glTF COLOR_0 beside a material without a texture: vertex colours times the factor.
    colors = np.full((8, 4), 128, dtype=np.uint8)
    mesh.visual.vertex_attributes["color"] = colors
    m = only(ss.Scene.from_trimesh(mesh))
    assert m.kind == "vertex"
    np.testing.assert_array_equal(m.vertex_colors, np.full((8, 3), np.float32(exact_srgb(128))))
    np.testing.assert_array_equal(m.color, np.float32([51, 102, 153]) / 255)
    # UVs but trimesh's empty material (an OBJ with vt and no mtl): no colour.
    mesh.visual = trimesh.visual.TextureVisuals(uv=np.zeros((8, 2)))
    assert ss.Scene.from_trimesh(mesh).materials == (None,)


OBJ = """mtllib {mtl}
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
vt 0 0
vt 1 0
vt 0 1
vt 1 1
usemtl {name}
f 1/1 2/2 3/3
f 2/2 4/4 3/3
"""


def test_obj_kd_is_read_as_linear_and_exact(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 0.5 0.25 0.1\nKa 0 0 0\n")
    (tmp_path / "a.obj").write_text(OBJ.format(mtl="m.mtl", name="red"))
    loaded = trimesh.load(tmp_path / "a.obj")
    geom = loaded if isinstance(loaded, trimesh.Trimesh) else next(iter(loaded.geometry.values()))
    # trimesh keeps Kd as uint8 round(255 Kd), no transfer function.
    np.testing.assert_array_equal(geom.visual.material.diffuse, [128, 64, 26, 255])
    m = only(ss.Scene.from_trimesh(tmp_path / "a.obj"))
    assert m.kind == "constant"
    assert m.color == tuple(float(x) for x in np.float32([0.5, 0.25, 0.1]))  # the file's numbers, not /255
    # Without the file's numbers: the uint8 / 255.
    geom.visual.material.kwargs.clear()
    np.testing.assert_array_equal(only(ss.Scene.from_trimesh(geom)).color, np.float32([128, 64, 26]) / 255)
    # An mtl without Kd: trimesh's default grey, no colour.
    (tmp_path / "n.mtl").write_text("newmtl plain\nKs 0.5 0.5 0.5\n")
    (tmp_path / "n.obj").write_text(OBJ.format(mtl="n.mtl", name="plain"))
    assert ss.Scene.from_trimesh(tmp_path / "n.obj").materials == (None,)


def test_obj_texture_uv_is_the_files_vt_and_kd_multiplies(tmp_path):
    pixels = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], dtype=np.uint8)
    Image.fromarray(pixels).save(tmp_path / "tex.png")
    (tmp_path / "t.mtl").write_text("newmtl tx\nKd 0.8 0.6 0.4\nmap_Kd tex.png\n")
    (tmp_path / "t.obj").write_text(OBJ.format(mtl="t.mtl", name="tx"))
    m = only(ss.Scene.from_trimesh(tmp_path / "t.obj"))
    assert m.kind == "texture"
    np.testing.assert_array_equal(m.texture, pixels)
    assert m.color == tuple(float(x) for x in np.float32([0.8, 0.6, 0.4]))
    loaded = trimesh.load(tmp_path / "t.obj")
    geom = loaded if isinstance(loaded, trimesh.Trimesh) else next(iter(loaded.geometry.values()))
    vt = {(0.0, 0.0, 0.0): (0, 0), (1.0, 0.0, 0.0): (1, 0), (0.0, 1.0, 0.0): (0, 1), (1.0, 1.0, 0.0): (1, 1)}
    # Each vertex keeps its vt as written (OBJ is v-up, as trimesh is).
    for v, t in zip(geom.vertices, m.uv, strict=True):
        assert tuple(t) == vt[tuple(float(x) for x in v)]
    # map_Kd without Kd: factor 1, not trimesh's default grey.
    (tmp_path / "u.mtl").write_text("newmtl tx\nmap_Kd tex.png\n")
    (tmp_path / "u.obj").write_text(OBJ.format(mtl="u.mtl", name="tx"))
    assert only(ss.Scene.from_trimesh(tmp_path / "u.obj")).color == (1.0, 1.0, 1.0)


def test_instanced_meshes_repeat_their_material_through_a_glb(tmp_path):
    red = box()
    red.visual.face_colors = [255, 0, 0, 255]
    plain = trimesh.creation.icosphere(subdivisions=1)
    s = trimesh.Scene()
    translate = trimesh.transformations.translation_matrix
    s.add_geometry(red, geom_name="red", node_name="a", transform=translate([2, 0, 0]))
    s.add_geometry(plain, geom_name="plain", node_name="b", transform=translate([0, 3, 0]))
    s.graph.update(frame_to="c", frame_from=s.graph.base_frame, matrix=translate([0, 0, 4]), geometry="red")
    assert len(s.geometry) == 2 and len(s.graph.nodes_geometry) == 3

    scene = ss.Scene.from_trimesh(s)
    assert len(scene.meshes) == len(scene.materials) == 3
    by_centre = {tuple(np.round(v.mean(axis=0), 6)): m for (v, _), m in zip(scene.meshes, scene.materials, strict=True)}
    assert by_centre[(0.0, 3.0, 0.0)] is None
    a, c = by_centre[(2.0, 0.0, 0.0)], by_centre[(0.0, 0.0, 4.0)]
    assert a is c and a.kind == "face"  # one Material, shared by the nodes
    np.testing.assert_array_equal(a.face_colors, np.tile(np.float32([1, 0, 0]), (12, 1)))

    path = tmp_path / "scene.glb"
    s.export(path)
    back = ss.Scene.from_trimesh(path)
    kinds = sorted(
        (tuple(np.round(v.mean(axis=0), 6)), None if m is None else m.kind)
        for (v, _), m in zip(back.meshes, back.materials, strict=True)
    )
    # glb keeps the instancing, and holds face colours as vertex colours.
    assert len(trimesh.load(path).geometry) == 2
    assert sum(m is not None for m in back.materials) == 2 and len({id(m) for m in back.materials}) == 2
    assert kinds == [((0.0, 0.0, 4.0), "vertex"), ((0.0, 3.0, 0.0), None), ((2.0, 0.0, 0.0), "vertex")]
    for (_, faces), m in zip(back.meshes, back.materials, strict=True):
        if m is not None:
            np.testing.assert_array_equal(
                m.vertex_colors[faces], np.ones((12, 3, 1), np.float32) * np.float32([1, 0, 0])
            )


def test_merged_primitives_give_face_colours():
    mesh = box()
    materials = trimesh.visual.material.MultiMaterial(
        [PBRMaterial(baseColorFactor=(1.0, 0, 0)), PBRMaterial(baseColorFactor=(0, 0, 1.0))]
    )
    face_materials = [0] * 4 + [1] * 8
    mesh.visual = trimesh.visual.TextureVisuals(material=materials, face_materials=face_materials)
    m = only(ss.Scene.from_trimesh(mesh))
    assert m.kind == "face"
    np.testing.assert_array_equal(m.face_colors, np.float32([[1, 0, 0]] * 4 + [[0, 0, 1]] * 8))


def test_scene_with_materials_pickles_and_compares():
    mesh, _ = textured_box(Image.new("RGB", (4, 2), (9, 99, 199)), factor=(0.5, 0.5, 0.5))
    scene = ss.Scene.from_trimesh(mesh)
    back = pickle.loads(pickle.dumps(scene))
    assert back.materials == scene.materials and back.materials[0] is not scene.materials[0]
    assert repr(back) == repr(scene)
    m = scene.materials[0]
    assert hash(back.materials[0]) == hash(m)
    assert m != Material("texture", color=m.color, uv=m.uv, texture=m.texture + np.uint8(1))
    assert m != Material("constant", color=m.color)
    assert "texture" in repr(m) and "(8, 2)" in repr(m)
    # Old pickles (no materials yet) load with none.
    state = back.__getstate__()
    del state["_materials"]
    old = ss.Scene.__new__(ss.Scene)
    old.__setstate__(state)
    assert old.materials == (None,)


def test_arrays_are_read_only_and_not_copied_needlessly():
    colors = np.full((5, 3), 0.5, dtype=np.float32)
    m = Material("vertex", vertex_colors=colors)
    assert np.shares_memory(m.vertex_colors, colors)
    assert not m.vertex_colors.flags.writeable and colors.flags.writeable
    with pytest.raises(ValueError):
        m.vertex_colors[0, 0] = 1.0
    with pytest.raises(AttributeError):
        m.kind = "face"
    # Other dtypes and layouts are converted.
    f64 = Material("face", face_colors=np.full((3, 6), 0.25)[:, ::2])
    assert f64.face_colors.dtype == np.float32 and f64.face_colors.flags.c_contiguous


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"kind": "metal"}, ValueError, "kind"),
        ({"kind": "vertex"}, ValueError, "vertex_colors"),
        ({"kind": "constant", "uv": np.zeros((3, 2))}, ValueError, "uv"),
        ({"kind": "texture", "uv": np.zeros((3, 2))}, ValueError, "texture"),
        ({"kind": "constant", "color": (0.5, 0.5)}, ValueError, "color"),
        ({"kind": "constant", "color": (0.5, 1.5, 0.5)}, ValueError, "color"),
        ({"kind": "constant", "color": (0.5, np.nan, 0.5)}, ValueError, "color"),
        ({"kind": "vertex", "vertex_colors": np.zeros((4, 4))}, ValueError, "vertex_colors"),
        ({"kind": "vertex", "vertex_colors": np.full((4, 3), 255, np.uint8)}, TypeError, "srgb_to_linear"),
        ({"kind": "face", "face_colors": np.full((4, 3), 2.0)}, ValueError, "face_colors"),
        ({"kind": "texture", "uv": np.zeros((3, 3)), "texture": np.zeros((2, 2, 3), np.uint8)}, ValueError, "uv"),
        (
            {"kind": "texture", "uv": np.full((3, 2), np.inf), "texture": np.zeros((2, 2, 3), np.uint8)},
            ValueError,
            "uv",
        ),
        ({"kind": "texture", "uv": np.zeros((3, 2)), "texture": np.zeros((2, 2, 4), np.uint8)}, ValueError, "texture"),
        ({"kind": "texture", "uv": np.zeros((3, 2)), "texture": np.zeros((2, 2, 3))}, TypeError, "texture"),
    ],
)
def test_bad_materials_are_refused_by_field(kwargs, error, match):
    with pytest.raises(error, match=match):
        Material(**kwargs)


def test_shapes_that_do_not_match_the_mesh_name_it():
    plain = box()
    bad = box()
    bad.visual = trimesh.visual.TextureVisuals(uv=np.zeros((3, 2)), image=Image.new("RGB", (2, 2)))
    with pytest.raises(ValueError, match=r"meshes\[1\].*3 rows of uv.*8 vertices"):
        ss.Scene.from_trimesh(trimesh.Scene([plain, bad]))
    m = Material("face", face_colors=np.zeros((11, 3), np.float32))
    with pytest.raises(ValueError, match=r"meshes\[4\].*11 rows of face_colors.*12 faces"):
        m.check("meshes[4]", 8, 12)
    m.check("meshes[4]", 8, 11)
    assert ss.Material is Material


def test_a_scene_takes_its_materials_by_keyword_checked_against_its_meshes():
    tri = (np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    red = Material("constant", color=(1.0, 0.0, 0.0))
    scene = ss.Scene(meshes=[tri, tri], materials=[red, None])
    assert scene.materials == (red, None)
    assert ss.Scene(meshes=[tri]).materials == (None,)
    with pytest.raises(ValueError, match="materials: 1 materials for 2 meshes"):
        ss.Scene(meshes=[tri, tri], materials=[red])
    with pytest.raises(TypeError, match=r"materials\[0\]"):
        ss.Scene(meshes=[tri], materials=["red"])
    faces = Material("face", face_colors=np.zeros((2, 3), np.float32))
    with pytest.raises(ValueError, match=r"materials\[0\]"):
        ss.Scene(meshes=[tri], materials=[faces])
