"""The colours a mesh's file carries, as the renderer's albedo reads them: one
:class:`Material` per mesh (``Scene.materials``, filled by
:meth:`softshadow.Scene.from_trimesh`).

A material is one of four kinds; the albedo at a surface point is ``color``
times what the kind gives there:

* ``"constant"``: 1 (the albedo is ``color``: glTF ``baseColorFactor``,
  OBJ ``Kd``);
* ``"vertex"``: ``vertex_colors`` interpolated over the triangle;
* ``"face"``: the triangle's row of ``face_colors``;
* ``"texture"``: ``texture`` sampled at the triangle's interpolated ``uv``.

Every colour is float32 *linear* RGB in [0, 1], except the texture, which
stays as the file encodes it: 8-bit sRGB, decoded by the core. Alpha is
dropped everywhere.

Where the values come from (:meth:`Material.from_trimesh`):

* trimesh holds vertex and face colours as uint8 RGBA; they are read as
  sRGB-encoded (as PLY, OBJ and trimesh's own viewer treat them) and decoded
  with the exact sRGB transfer function (:func:`srgb_to_linear`). That
  includes glTF's ``COLOR_0``, which the glTF spec calls linear: trimesh
  stores it as the same uint8 (floats times 255, no transfer function) and
  writes those bytes back unchanged on export, so the file's origin is lost.
* glTF's ``baseColorFactor`` is linear by the glTF spec. trimesh stores it
  as uint8 RGBA (``round(255 * f)``), so it arrives quantized to 1/255 and
  is read as ``value / 255`` (a float factor, set by hand, is kept as is).
  A glTF material without one is white, the spec's default (exporters leave
  it out); only a mesh without a material has no colour.
* OBJ's ``Kd`` is read as linear: it is a reflectance (MTL names no colour
  space). trimesh turns the file's floats into ``round(255 * Kd)``, a plain
  scaling with no transfer function, so the uint8 ``diffuse`` is no sRGB
  code and ``/ 255`` undoes trimesh's step. Where trimesh's OBJ loader kept
  the file's own numbers (``material.kwargs["kd"]``, still matching the
  stored colour), those exact values are used. A ``SimpleMaterial`` whose
  diffuse is trimesh's default grey (102, 102, 102) and that has no ``kd``
  holds no colour.
* With an ``map_Kd`` texture, OBJ's ``Kd`` multiplies it (the MTL spec);
  without a ``Kd`` line the factor is 1. glTF's ``baseColorFactor``
  multiplies its texture (the glTF spec); 1 where the file has none. A
  texture without UVs falls back to the factor alone (``"constant"``), or to
  glTF's ``COLOR_0`` times the factor (``"vertex"``) where the mesh has it;
  with a texture, ``COLOR_0`` is dropped (one source per mesh).

UV convention: ``uv`` is what trimesh gives, v pointing *up* the image, for
glTF (trimesh flips the file's v-down ``TEXCOORD_0`` on loading, and back on
export) and for OBJ (whose ``vt`` is already v-up). Row 0 of ``texture`` is
the top row of the image as stored. The sampler reads the continuous texel
coordinate ``(x, y) = (u * W, (1 - v) * H)``: texel ``(row i, column j)``
covers ``x`` in [j, j + 1) and ``y`` in [i, i + 1), its centre at
``u = (j + 0.5) / W``, ``v = 1 - (i + 0.5) / H``. UVs outside [0, 1] are
kept as the file gives them (glTF's default sampler repeats).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from . import _core

__all__ = ["Material", "MaterialKind", "srgb_to_linear"]

MaterialKind = Literal["constant", "vertex", "face", "texture"]
KINDS: tuple[str, ...] = ("constant", "vertex", "face", "texture")

#: The field each kind needs besides ``color`` (the texture kind needs two).
_NEEDS: dict[str, tuple[str, ...]] = {
    "constant": (),
    "vertex": ("vertex_colors",),
    "face": ("face_colors",),
    "texture": ("uv", "texture"),
}
_ARRAYS = ("vertex_colors", "face_colors", "uv", "texture")


#: uint8 sRGB code -> linear float32 (the core's decoding of code / 255).
_SRGB_LUT = _core.srgb_to_linear(np.arange(256) / 255.0)
_SRGB_LUT.flags.writeable = False


def srgb_to_linear(values: npt.ArrayLike) -> np.ndarray:
    """Linear float32 values of sRGB-encoded ones: uint8 codes (0-255, a
    table lookup) or floats (clipped to [0, 1]); decoded by the core with the
    exact sRGB transfer function (``c <= 0.04045 ? c / 12.92 : ((c + 0.055)
    / 1.055) ** 2.4``), as it decodes textures. 128 decodes to 0.2158605."""
    a = np.asarray(values)
    if a.dtype == np.uint8:
        return _SRGB_LUT[a]
    if a.dtype.kind != "f":
        raise TypeError(f"values: must be uint8 codes or floats in [0, 1], got dtype {a.dtype}")
    return _core.srgb_to_linear(np.ascontiguousarray(a, dtype=np.float64))


def _read_only(a: np.ndarray) -> np.ndarray:
    """``a`` itself when already read-only, else a read-only view (the caller's
    array keeps its own flag; nothing is copied)."""
    if a.flags.writeable:
        a = a.view()
        a.flags.writeable = False
    return a


def _unit_floats(value: Any, field: str, shape: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype.kind != "f":
        raise TypeError(
            f"{field}: must be linear float colours in [0, 1], got dtype {a.dtype} "
            "(decode uint8 sRGB codes with softshadow.materials.srgb_to_linear)"
        )
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{field}: must have shape {shape}, got {a.shape}")
    if a.size and not (np.isfinite(a).all() and a.min() >= 0.0 and a.max() <= 1.0):
        raise ValueError(f"{field}: must lie in [0, 1], got values in [{a.min()}, {a.max()}]")
    return _read_only(a)


@dataclass(frozen=True, slots=True, eq=False, repr=False)
class Material:
    """One mesh's albedo source (module docstring: kinds, colour spaces, UVs).

    ``Material("constant", color=(r, g, b))``,
    ``Material("vertex", vertex_colors=(V, 3))``,
    ``Material("face", face_colors=(F, 3))``,
    ``Material("texture", uv=(V, 2), texture=(H, W, 3), color=factor)``.

    kind
        ``"constant"``, ``"vertex"``, ``"face"`` or ``"texture"``.
    color
        Linear RGB in [0, 1] multiplying what the kind gives (the albedo
        itself for ``"constant"``); default white. Stored as a tuple of
        three floats (float32 values).
    vertex_colors, face_colors
        (V, 3) / (F, 3) float32 linear RGB in [0, 1], one row per vertex /
        face of the mesh; only for their kind.
    uv
        (V, 2) float32, one per vertex, v up (row ``(1 - v) * H``); only for
        ``"texture"``.
    texture
        (H, W, 3) uint8 sRGB, row 0 the image's top row; only for
        ``"texture"``.

    Arrays are stored C-contiguous and read-only; one already of the right
    dtype and layout is kept without a copy (a read-only view of it). Equal
    when the kind, the colour and every array are equal.
    """

    kind: MaterialKind
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    vertex_colors: np.ndarray | None = None
    face_colors: np.ndarray | None = None
    uv: np.ndarray | None = None
    texture: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind: must be one of {', '.join(KINDS)}, got {self.kind!r}")
        needs = _NEEDS[self.kind]
        for field in _ARRAYS:
            given = getattr(self, field) is not None
            if given != (field in needs):
                what = "needs" if field in needs else "takes no"
                raise ValueError(f"{field}: a {self.kind!r} material {what} {field}")
        c = np.asarray(self.color)
        if c.dtype.kind not in "fiu" or c.shape != (3,):
            raise ValueError(f"color: must be 3 numbers (linear R, G, B), got {self.color!r}")
        c = c.astype(np.float32)
        if not (np.isfinite(c).all() and c.min() >= 0.0 and c.max() <= 1.0):
            raise ValueError(f"color: must lie in [0, 1], got {c.tolist()}")
        object.__setattr__(self, "color", (float(c[0]), float(c[1]), float(c[2])))
        if self.vertex_colors is not None:
            object.__setattr__(self, "vertex_colors", _unit_floats(self.vertex_colors, "vertex_colors", "(V, 3)"))
        if self.face_colors is not None:
            object.__setattr__(self, "face_colors", _unit_floats(self.face_colors, "face_colors", "(F, 3)"))
        if self.uv is not None:
            uv = np.asarray(self.uv)
            if uv.dtype.kind not in "fiu":
                raise TypeError(f"uv: must be numbers, got dtype {uv.dtype}")
            uv = np.ascontiguousarray(uv, dtype=np.float32)
            if uv.ndim != 2 or uv.shape[1] != 2:
                raise ValueError(f"uv: must have shape (V, 2), got {uv.shape}")
            if not np.isfinite(uv).all():
                raise ValueError("uv: must be finite")
            object.__setattr__(self, "uv", _read_only(uv))
        if self.texture is not None:
            t = np.asarray(self.texture)
            if t.dtype != np.uint8:
                raise TypeError(f"texture: must be uint8 sRGB, got dtype {t.dtype}")
            if t.ndim != 3 or t.shape[2] != 3 or t.shape[0] < 1 or t.shape[1] < 1:
                raise ValueError(f"texture: must have shape (H, W, 3) with H, W >= 1, got {t.shape}")
            object.__setattr__(self, "texture", _read_only(np.ascontiguousarray(t)))

    def check(self, name: str, vertices: int, faces: int) -> None:
        """ValueError naming ``name`` (``meshes[k]``) unless the per-vertex or
        per-face rows match a mesh of ``vertices`` vertices and ``faces``
        faces."""
        rows = {"vertex_colors": (vertices, "vertices"), "uv": (vertices, "vertices"), "face_colors": (faces, "faces")}
        for field, (want, per) in rows.items():
            a = getattr(self, field)
            if a is not None and len(a) != want:
                raise ValueError(f"{name}: its material has {len(a)} rows of {field}, the mesh {want} {per}")

    def to_core(self) -> tuple[str, tuple[float, float, float], np.ndarray | None, np.ndarray | None]:
        """``(kind, color, array1, array2)`` for the core: ``array1`` is the
        (V, 3) / (F, 3) float32 colours for ``"vertex"`` / ``"face"``, the
        (V, 2) float32 ``uv`` for ``"texture"`` (``array2``: the (H, W, 3)
        uint8 texture); None where the kind has none. The arrays are the
        stored ones (C-contiguous, read-only), not copies."""
        if self.kind == "vertex":
            return (self.kind, self.color, self.vertex_colors, None)
        if self.kind == "face":
            return (self.kind, self.color, self.face_colors, None)
        if self.kind == "texture":
            return (self.kind, self.color, self.uv, self.texture)
        return (self.kind, self.color, None, None)

    @staticmethod
    def from_trimesh(mesh: Any, name: str = "mesh") -> Material | None:
        """The material of a ``trimesh.Trimesh``'s visual, or None where it
        holds no colour (trimesh's default grey: a ``ColorVisuals`` whose
        ``kind`` is None, an empty ``TextureVisuals``). Shapes that do not
        match the mesh raise ValueError naming ``name``. See the module
        docstring for what each visual gives."""
        try:
            material = _from_visual(getattr(mesh, "visual", None), len(mesh.vertices), len(mesh.faces))
        except (ValueError, TypeError) as e:
            raise ValueError(f"{name}: {e}") from None
        if material is not None:
            material.check(name, len(mesh.vertices), len(mesh.faces))
        return material

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Material):
            return NotImplemented
        if self.kind != other.kind or self.color != other.color:
            return False
        for field in _ARRAYS:
            a, b = getattr(self, field), getattr(other, field)
            if (a is None) != (b is None) or (a is not None and not np.array_equal(a, b)):
                return False
        return True

    def __hash__(self) -> int:
        shapes = tuple(None if getattr(self, f) is None else getattr(self, f).shape for f in _ARRAYS)
        return hash((self.kind, self.color, shapes))

    def __reduce__(self) -> tuple[Any, ...]:
        return (Material, (self.kind, self.color, self.vertex_colors, self.face_colors, self.uv, self.texture))

    def __repr__(self) -> str:
        r, g, b = self.color
        parts = [f"{self.kind!r}", f"color=({r:.6g}, {g:.6g}, {b:.6g})"]
        parts += [f"{f}={getattr(self, f).shape}" for f in _ARRAYS if getattr(self, f) is not None]
        return f"Material({', '.join(parts)})"


# --- trimesh visuals ---------------------------------------------------------


def _factor(value: Any) -> np.ndarray | None:
    """A material's linear RGB factor from trimesh's stored colour: uint8
    (0-255, trimesh's storage) divided by 255, floats kept; None for None."""
    if value is None:
        return None
    a = np.asarray(value)
    if a.dtype.kind in "iu":
        a = a / 255.0
    a = np.asarray(a, dtype=np.float64).reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.size not in (3, 4):
        raise ValueError(f"material colour must be RGB or RGBA, got {np.shape(value)}")
    return a[:3]


def _rgb(a: np.ndarray) -> tuple[float, float, float]:
    return (float(a[0]), float(a[1]), float(a[2]))


def _kd(material: Any) -> np.ndarray | None:
    """A ``SimpleMaterial``'s diffuse colour where it is the file's (or the
    user's), None where it is trimesh's default grey."""
    from trimesh.visual.color import DEFAULT_COLOR, to_rgba

    diffuse = getattr(material, "diffuse", None)
    if diffuse is None:
        return None
    kwargs = getattr(material, "kwargs", None) or {}
    kd = kwargs.get("kd")
    if kd is not None:
        # trimesh's OBJ loader keeps the MTL's own numbers beside the uint8
        # colour: exact where they still match it (none changed since).
        try:
            exact = np.broadcast_to(np.asarray(kd, dtype=np.float64).reshape(-1), (3,))
            if np.array_equal(to_rgba(exact.copy())[:3], np.asarray(diffuse)[:3]):
                return exact
        except (TypeError, ValueError):
            pass
        return _factor(diffuse)
    d = np.asarray(diffuse)
    if d.dtype == np.uint8 and np.array_equal(d.reshape(-1), DEFAULT_COLOR):
        return None
    return _factor(diffuse)


def _is_placeholder(image: Any) -> bool:
    """trimesh's stand-in image of an empty material (2x2 grey RGBA)."""
    from trimesh.visual.material import color_image

    if getattr(image, "size", None) != (2, 2) or getattr(image, "mode", None) != "RGBA":
        return False
    return bool(image.tobytes() == color_image().tobytes())


def _rgb8(image: Any) -> np.ndarray:
    """(H, W, 3) uint8 of a PIL image (or an array): the encoded values,
    alpha dropped; greyscale, palette and other modes through
    ``convert("RGB")``, 16-bit greyscale by its high byte."""
    mode = getattr(image, "mode", None)
    if mode is None:
        a = np.asarray(image)
        if a.ndim == 2:
            a = a[:, :, None]
        if a.dtype != np.uint8 or a.ndim != 3 or a.shape[2] not in (1, 3, 4):
            raise ValueError(f"texture image must be uint8 (H, W[, 1|3|4]), got {a.dtype} {a.shape}")
        a = a[:, :, :3] if a.shape[2] >= 3 else np.repeat(a, 3, axis=2)
        return np.ascontiguousarray(a)
    if mode == "RGB":
        return np.asarray(image)
    if mode == "I" or mode.startswith("I;16"):
        grey = (np.clip(np.asarray(image), 0, 65535).astype(np.uint32) >> 8).astype(np.uint8)
        return np.repeat(grey[:, :, None], 3, axis=2)
    return np.asarray(image.convert("RGB"))


def _vertex_colors(colors: Any) -> np.ndarray:
    """(N, 3) linear float32 of colours as trimesh stores them (uint8 RGBA,
    sRGB-encoded); other dtypes go through trimesh's own ``to_rgba`` first,
    as a ``ColorVisuals`` would."""
    from trimesh.visual.color import to_rgba

    c = np.asarray(colors)
    if c.dtype == np.uint16:
        c = (c >> 8).astype(np.uint8)
    if c.dtype != np.uint8:
        c = to_rgba(c)
    if c.ndim != 2 or c.shape[1] not in (3, 4):
        raise ValueError(f"colours must have shape (n, 3) or (n, 4), got {c.shape}")
    return srgb_to_linear(c[:, :3])


def _from_visual(visual: Any, vertices: int, faces: int) -> Material | None:
    kind = getattr(visual, "kind", None)
    if kind == "vertex":
        return Material("vertex", vertex_colors=_vertex_colors(visual.vertex_colors))
    if kind == "face":
        return Material("face", face_colors=_vertex_colors(visual.face_colors))
    if kind == "texture":
        return _from_texture(visual, vertices, faces)
    return None


def _constant_of(material: Any) -> tuple[np.ndarray | None, Any]:
    """(linear factor or None, image or None) of one trimesh material."""
    from trimesh.visual.material import PBRMaterial, SimpleMaterial

    if isinstance(material, PBRMaterial):
        # A glTF material without baseColorFactor is white (the spec's
        # default, which exporters leave out), not uncoloured.
        factor = _factor(material.baseColorFactor)
        return (np.ones(3) if factor is None else factor), material.baseColorTexture
    if isinstance(material, SimpleMaterial):
        image = material.image
        return _kd(material), (None if image is None or _is_placeholder(image) else image)
    return None, None


def _from_texture(visual: Any, vertices: int, faces: int) -> Material | None:
    from trimesh.visual.material import MultiMaterial

    material = getattr(visual, "material", None)
    if isinstance(material, MultiMaterial):
        return _from_multi(material, getattr(visual, "face_materials", None), faces)
    factor, image = _constant_of(material)
    color = (1.0, 1.0, 1.0) if factor is None else _rgb(factor)
    uv = getattr(visual, "uv", None)
    if image is not None and uv is not None:
        return Material("texture", color=color, uv=np.asarray(uv), texture=_rgb8(image))
    # glTF's COLOR_0 beside a material: trimesh keeps it as a vertex
    # attribute; it multiplies the base colour (the glTF spec).
    attributes = getattr(visual, "vertex_attributes", None)
    extra = attributes.get("color") if attributes is not None else None
    if extra is not None and len(extra) == vertices:
        return Material("vertex", color=color, vertex_colors=_vertex_colors(extra))
    if factor is not None:
        return Material("constant", color=color)
    return None


def _from_multi(material: Any, face_materials: Any, faces: int) -> Material | None:
    """Primitives merged into one mesh (``merge_primitives=True``): per-face
    colours when every material is a constant colour; None where one has a
    texture (one texture per mesh) or no colour."""
    if face_materials is None or len(face_materials) != faces:
        return None
    constants = []
    for m in material.materials:
        factor, image = _constant_of(m)
        if image is not None:
            return None
        if factor is None:
            return None
        constants.append(factor)
    table = np.array(constants, dtype=np.float32).reshape(-1, 3)
    index = np.asarray(face_materials, dtype=np.int64)
    if index.size and (index.min() < 0 or index.max() >= len(table)):
        raise ValueError(f"face_materials must index {len(table)} materials, got [{index.min()}, {index.max()}]")
    return Material("face", face_colors=table[index])
