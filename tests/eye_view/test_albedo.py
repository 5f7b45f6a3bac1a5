"""The albedo each pixel is shaded with: the meshes' colours, materials and
textures as ``Scene.from_trimesh`` reads them (src/eye/albedo.rs)."""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss

trimesh = pytest.importorskip("trimesh")
Image = pytest.importorskip("PIL.Image")


def _srgb(c: np.ndarray) -> np.ndarray:
    x = np.asarray(c, np.float64) / 255.0
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


# A 2 x 2 texture: red, green (top row), blue, white (bottom row).
TEXELS = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)


def _textured_quad(factor: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)) -> trimesh.Trimesh:
    # The floor quad [-1, 1]^2 at y = 0, u along +x, v along -z (v up the
    # image: the image's top row at z = -1).
    v = np.array([[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]], float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(TEXELS), baseColorFactor=[int(round(255 * c)) for c in factor]
    )
    return trimesh.Trimesh(v, f, visual=trimesh.visual.TextureVisuals(uv=uv, material=material), process=False)


def _camera(resolution: tuple[int, int] = (64, 64)) -> ss.Camera:
    # Straight down onto the quad, image up along -z: pixel (row, col) sees
    # x growing with col, z growing with row.
    return ss.Camera.look_at(eye=(0, 6, 0), target=(0, 0, 0), up=(0, 0, -1), fov_y=20.0, resolution=resolution)


def _at(img: ss.Image, x: float, z: float) -> np.ndarray:
    """The albedo of the pixel whose point is nearest (x, 0, z)."""
    d = np.linalg.norm(img.position[..., [0, 2]] - [x, z], axis=-1)
    d[~img.mask] = np.inf
    return img.albedo[np.unravel_index(np.argmin(d), d.shape)]


def test_a_textured_gltf_shows_its_texture_in_the_albedo(tmp_path):
    path = tmp_path / "quad.glb"
    trimesh.Scene([_textured_quad()]).export(path)
    scene = ss.Scene.from_trimesh(path)
    assert scene.materials[0] is not None and scene.materials[0].kind == "texture"
    light = ss.RectLight((0, 3, 0), (0, -1, 0), (0, 0, 1), 0.5)
    img = ss.render(scene, light, _camera())
    assert img.albedo.shape == (64, 64, 3) and img.albedo.dtype == np.float32
    # Each quadrant's centre is a texel's centre: its colour, decoded.
    want = _srgb(TEXELS)
    for (x, z), (i, j) in {(-0.5, -0.5): (0, 0), (0.5, -0.5): (0, 1), (-0.5, 0.5): (1, 0), (0.5, 0.5): (1, 1)}.items():
        np.testing.assert_allclose(_at(img, x, z), want[i, j], atol=0.03)
    # Between two texels the blend is linear in the decoded values.
    np.testing.assert_allclose(_at(img, 0.0, -0.5), 0.5 * (want[0, 0] + want[0, 1]), atol=0.05)
    # No surface: 0. The shading takes the albedo: unshadowed = albedo E / pi.
    assert np.all(img.albedo[~img.mask] == 0.0)
    m = img.mask
    e = light.irradiance_at(img.position[m], img.normal[m].astype(np.float64))
    np.testing.assert_allclose(img.unshadowed[m], img.albedo[m] * e / np.pi, rtol=1e-5, atol=1e-8)
    # albedo= overrides the file's colours.
    grey = ss.render(scene, light, _camera(), albedo=0.5)
    assert np.all(grey.albedo[m] == 0.5)


def test_the_base_colour_factor_multiplies_the_texture(tmp_path):
    path = tmp_path / "quad.glb"
    trimesh.Scene([_textured_quad((0.5, 1.0, 0.25, 1.0))]).export(path)
    img = ss.render(ss.Scene.from_trimesh(path), ss.RectLight((0, 3, 0), (0, -1, 0), (0, 0, 1), 0.5), _camera())
    white = _srgb(TEXELS)[1, 1]
    # trimesh stores the factor as 8 bits: 128/255, 255/255, 64/255.
    np.testing.assert_allclose(_at(img, 0.5, 0.5), white * [128 / 255, 1.0, 64 / 255], atol=0.03)


def test_vertex_and_face_colours_are_read():
    light = ss.RectLight((0, 3, 0), (0, -1, 0), (0, 0, 1), 0.5)
    vertex = _textured_quad()
    vertex.visual = trimesh.visual.ColorVisuals(
        vertex, vertex_colors=np.array([[255, 0, 0, 255], [255, 0, 0, 255], [0, 0, 255, 255], [0, 0, 255, 255]])
    )
    img = ss.render(ss.Scene.from_trimesh(vertex), light, _camera())
    # Red at z = +1, blue at z = -1: the middle is their blend.
    np.testing.assert_allclose(_at(img, 0.0, 0.9), [0.95, 0, 0.05], atol=0.05)
    np.testing.assert_allclose(_at(img, 0.0, 0.0), [0.5, 0, 0.5], atol=0.05)
    face = _textured_quad()
    face.visual = trimesh.visual.ColorVisuals(face, face_colors=np.array([[255, 255, 0, 255], [0, 255, 255, 255]]))
    img = ss.render(ss.Scene.from_trimesh(face), light, _camera())
    # Face 0 (0, 1, 2) lies below the diagonal x = -z, face 1 above it.
    np.testing.assert_allclose(_at(img, 0.5, 0.5), [1, 1, 0], atol=1e-6)
    np.testing.assert_allclose(_at(img, -0.5, -0.5), [0, 1, 1], atol=1e-6)


def test_uncoloured_meshes_take_the_default_and_a_bad_material_is_named():
    light = ss.RectLight((0, 3, 0), (0, -1, 0), (0, 0, 1), 0.5)
    plain = ss.Scene(meshes=[(np.array([[-1, 0, 1], [1, 0, 1], [1, 0, -1.0]]), np.array([[0, 1, 2]]))])
    img = ss.render(plain, light, _camera())
    assert np.all(img.albedo[img.mask] == np.float32(0.8))
    scene = ss.Scene.from_trimesh(_textured_quad())
    # The scene's mesh replaced by one with fewer vertices: its UVs no longer fit.
    scene.meshes[0] = (np.asarray(scene.meshes[0][0])[:3], np.array([[0, 1, 2]], np.uint32))
    with pytest.raises(ValueError, match=r"materials\[0\]"):
        ss.render(scene, light, _camera())
