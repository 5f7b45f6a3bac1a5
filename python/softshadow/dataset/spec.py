"""The dataset spec: a TOML file read into frozen dataclasses, validated on load.

Every field is checked as it is read (:mod:`.fields`): its type, its range
(:mod:`.limits`), finiteness; unknown fields are refused; every error is a
:class:`SpecError` naming the field's dotted path (``objects[1].scale``) and
what is allowed. Nothing is rendered or written before a spec loads.
docs/dataset.md describes every field.

Units: world units (the ground is the plane y = 0, +y up), angles in
degrees. Azimuths are measured from +x toward +z, elevations above the
horizontal plane.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import inspect
import json
import os
import re
import stat
import sys
from dataclasses import asdict, dataclass, field
from types import ModuleType
from typing import Any

from .._extras import require
from ..io import exr_compression
from . import limits as L
from .build import MeshError, check_mesh_file
from .fields import IntRange, Range, SpecError, Table
from .files import sha256_file

Color = tuple[Range, Range, Range]

PRIMITIVES = ["bunny", "box", "sphere", "torus"]
OBJECT_KINDS = [*PRIMITIVES, "mesh"]
CHANNELS = ["visibility", "shaded", "unshadowed", "depth", "normal", "position", "mesh_id", "mask", "albedo"]
"""Channel groups an item's EXR may hold (``position`` and ``albedo`` only on request)."""
DEFAULT_CHANNELS = ["visibility", "shaded", "unshadowed", "depth", "normal", "mesh_id", "mask"]
SHADING_CHANNELS = {"shaded", "unshadowed", "albedo"}
"""The channels of ``ss.render``'s shading (not the Mitsuba reference's)."""
LIGHT_KINDS = ["rect", "disk", "sphere", "sun"]
PLACED_KINDS = ("rect", "disk", "sphere")
"""The area lights, placed at ``distance`` from ``target`` (the sun has a direction only)."""
LIGHT_KEYS: dict[str, tuple[str, ...]] = {
    "size": ("rect",),
    "aspect": ("rect",),
    "radius": ("disk", "sphere"),
    "distance": PLACED_KINDS,
    "target": PLACED_KINDS,
    "radiance": PLACED_KINDS,
    "angular_size": ("sun",),
    "irradiance": ("sun",),
}
"""The ``[[lights]]`` keys that only some kinds take (the others take
``kind``, ``weight``, ``azimuth`` and ``elevation``)."""
COLORS = ["file", "albedo"]
"""``colors`` of a ``kind = "mesh"`` object: the file's own colours where it
has them, or the sampled ``albedo`` everywhere."""
MESH_EXTENSIONS = {".obj", ".ply", ".stl", ".off", ".glb", ".gltf", ".dae", ".3mf"}
"""The mesh files a folder contributes (formats trimesh reads)."""
REFERENCE = "reference"
RESERVED_NAMES = {"spec.toml", "dataset.json", "manifest.jsonl", "lock"}
"""The files of ``--out`` itself, which ``outputs.folder`` may not be."""
FOLDER_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")
"""What ``outputs.folder`` may be: one plain name (also checked in ``dataset.json``)."""


@dataclass(frozen=True)
class GroundSpec:
    enabled: bool
    size: float
    albedo: Color


@dataclass(frozen=True)
class ObjectSpec:
    kind: str
    path: str | None
    """As written in the spec (``kind = "mesh"``)."""
    files: tuple[str, ...]
    """Absolute paths of the mesh files (one for a file, the folder's mesh files sorted)."""
    count: IntRange
    placement: str
    height: Range
    layout: str
    x: Range
    z: Range
    grid: tuple[int, int]
    spacing: tuple[float, float]
    fill: float
    jitter: float
    scale: Range
    stretch: tuple[Range, Range, Range]
    yaw: Range
    tilt: Range
    albedo: Color
    colors: str = "albedo"
    """``"file"``: a mesh file's own colours and texture where it has them
    (``kind = "mesh"`` only); ``"albedo"``: the sampled ``albedo``."""


@dataclass(frozen=True)
class LightSpec:
    kind: str
    weight: float
    azimuth: Range
    elevation: Range
    size: Range
    aspect: Range
    distance: Range
    target: tuple[float, float, float]
    angular_size: Range
    power: Range
    """``radiance`` of a rectangle, disk or sphere, ``irradiance`` of the sun."""
    radius: Range = (0.0, 0.0)
    """A disk's or a sphere's radius."""


@dataclass(frozen=True)
class CameraSpec:
    azimuth: Range
    elevation: Range
    distance: Range
    look_at_height: Range
    target_x: Range
    target_z: Range
    fov_y: Range
    resolution: tuple[int, int]


@dataclass(frozen=True)
class MethodSpec:
    name: str
    options: dict[str, Any]
    map_resolution: tuple[int, int] | None
    normal_offset: float | None
    depth_bias: float | None
    backend: str


@dataclass(frozen=True)
class OutputSpec:
    channels: tuple[str, ...]
    light_maps: bool
    previews: bool
    folder: str
    compression: str = "zip"


@dataclass(frozen=True)
class Spec:
    seed: int
    count: int
    ground: GroundSpec
    objects: tuple[ObjectSpec, ...]
    lights: tuple[LightSpec, ...]
    camera: CameraSpec
    method: MethodSpec
    outputs: OutputSpec
    text: str = field(repr=False, compare=False)
    """The spec file's text, stored in ``--out``."""
    folder: str = field(repr=False, compare=False)
    """The spec file's folder (relative mesh paths resolve against it)."""
    mesh_hashes: dict[str, str] = field(repr=False, compare=False, default_factory=dict)
    """sha256 of every mesh file, by absolute path."""
    views: int = 1
    """Consecutive items that share one scene (objects and ground), each with
    its own light and camera: items k and j share it when k // views ==
    j // views (:func:`.sampling.scene_item`)."""
    lights_per_item: IntRange = (1, 1)
    """How many lights an item draws (each from the ``[[lights]]`` tables by
    weight); more than 1 possible makes every item of the spec a several-light
    item (:attr:`several_lights`)."""
    mesh_colors: dict[str, bool] = field(repr=False, compare=False, default_factory=dict)
    """Whether each mesh file carries colours (a material, vertex or face
    colours, a texture), by absolute path."""

    @property
    def several_lights(self) -> bool:
        """Whether items may have more than one light: then every item is
        rendered with a list of lights (channels ``V.0``, ``V.1``, ...; the
        record's ``lights``), even one that drew a single light."""
        return self.lights_per_item[1] > 1

    def file_colors(self, o: ObjectSpec, path: str) -> bool:
        """Whether instances of ``o`` drawing the file ``path`` keep its own colours."""
        return o.kind == "mesh" and o.colors == "file" and self.mesh_colors.get(path, False)

    def canonical(self) -> dict[str, Any]:
        """What defines the items (everything but ``count``), as JSON values:
        mesh files appear by their path relative to the spec's folder and
        their sha256, so moving the spec with its meshes keeps its hash.
        Fields added since the first format are left out where they change
        nothing (``views = 1``, one light, ``compression = "zip"``, a light's
        ``radius`` for a rectangle or the sun, an object's ``colors`` unless
        its files' own colours are used), so that specs from before them
        keep their hash (and their output folders resume)."""
        d = asdict(self)
        for name in ("text", "folder", "mesh_hashes", "mesh_colors", "count"):
            d.pop(name)
        for o, obj in zip(self.objects, d["objects"], strict=True):
            if not any(self.file_colors(o, f) for f in o.files):
                del obj["colors"]  # as before the field: the sampled albedo
            obj["files"] = [[self.relative(f), self.mesh_hashes[f]] for f in obj["files"]]
        for light in d["lights"]:
            if light["kind"] not in ("disk", "sphere"):
                del light["radius"]
        if d["outputs"]["compression"] == "zip":
            # The default, left out so that specs from before the field
            # keep their hash (and their output folders resume).
            del d["outputs"]["compression"]
        if d["views"] == 1:
            del d["views"]  # likewise
        if tuple(d["lights_per_item"]) == (1, 1):
            del d["lights_per_item"]  # likewise
        return json.loads(json.dumps(d))

    @functools.cached_property
    def hash(self) -> str:
        """sha256 of :meth:`canonical` (the spec's identity in ``--out``);
        computed once per spec object (every item's record names it)."""
        text = json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def relative(self, path: str) -> str:
        return os.path.relpath(path, self.folder).replace(os.sep, "/")


def shading_available() -> bool:
    """Whether ``ss.render`` shades (``albedo=``, ``Image.shaded``)."""
    import softshadow as ss

    return "albedo" in inspect.signature(ss.render).parameters


def _toml() -> ModuleType:
    """tomllib (Python 3.11+) or tomli, the ``dataset`` extra's backport for 3.10."""
    if sys.version_info >= (3, 11):
        try:
            return require("tomllib", "dataset", "reading a spec (TOML)")
        except ImportError:
            pass  # a stripped Python: the backport does as well
    return require("tomli", "dataset", "reading a spec (TOML)")


def load_spec(path: str | os.PathLike[str]) -> Spec:
    """Reads and validates a spec file; raises :class:`SpecError` naming the field."""
    tomllib = _toml()
    p = os.path.abspath(os.fspath(path))
    try:
        with open(p, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise SpecError(f"spec: cannot read {p!r}: {e.strerror or e}") from e
    if len(raw) > 1 << 20:
        raise SpecError(f"spec: {p!r} is {len(raw)} bytes; a spec is at most 1 MiB")
    try:
        text = raw.decode("utf-8")
        data = tomllib.loads(text)
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise SpecError(f"spec: {p!r} is not valid TOML: {e}") from e
    return parse_spec(data, text=text, folder=os.path.dirname(p))


def parse_spec(data: dict[str, Any], *, text: str = "", folder: str = ".") -> Spec:
    """Validates a parsed TOML document (see :func:`load_spec`)."""
    top = Table(data, "")
    folder = os.path.abspath(folder)
    seed = top.integer("seed", 0, 0, L.MAX_SEED)
    count = top.integer("count", 1, 1, L.MAX_COUNT)
    views = top.integer("views", 1, 1, L.MAX_VIEWS)
    ground = _ground(top.table("ground"))
    colored: dict[str, bool] = {}
    objects = tuple(_object(t, folder, colored) for t in top.tables("objects", most=L.MAX_OBJECT_ENTRIES))
    instances = sum(_most_instances(o) for o in objects)
    if instances > L.MAX_INSTANCES:
        raise SpecError(f"objects: up to {instances} instances per item; at most {L.MAX_INSTANCES}")
    if not ground.enabled and all(_most_instances(o) == 0 for o in objects):
        raise SpecError("objects: no objects and no ground: an item would have no surface")
    lights = tuple(_light(t) for t in top.tables("lights", most=L.MAX_LIGHT_ENTRIES, least=1))
    lights_per_item = top.int_range("lights_per_item", 1, 1, _most_lights())
    camera = _camera(top.table("camera", required=True))
    method = _method(top.table("method"))
    outputs = _outputs(top.table("outputs"), method, lights, lights_per_item)
    top.done()
    _check_light_kinds(lights, method, outputs.light_maps)
    hashes = {f: sha256_file(f) for o in objects for f in o.files}
    return Spec(
        seed, count, ground, objects, lights, camera, method, outputs, text, folder, hashes, views,
        lights_per_item=lights_per_item, mesh_colors=colored,
    )  # fmt: skip


def _most_lights() -> int:
    """``lights_per_item``'s bound: this module's and the core's (one call's lights)."""
    import softshadow as ss

    return min(L.MAX_LIGHTS_PER_ITEM, int(ss.limits().get("lights", 1)))


def _ground(t: Table) -> GroundSpec:
    g = GroundSpec(
        enabled=t.boolean("enabled", True),
        size=t.number("size", 8.0, 0.0, L.MAX_COORDINATE, open_lo=True),
        albedo=t.color("albedo", 0.8),
    )
    t.done()
    return g


def _object(t: Table, folder: str, colored: dict[str, bool]) -> ObjectSpec:
    """One ``[[objects]]`` table; ``colored`` gets whether each of its mesh
    files carries colours."""
    kind = t.choice("kind", OBJECT_KINDS)
    path: str | None = None
    files: tuple[str, ...] = ()
    colors = "albedo"
    if kind == "mesh":
        path = t.string("path")
        colors = t.choice("colors", COLORS, "file")
        files = _mesh_files(t.name("path"), path, folder, colored, colors=colors == "file")
    elif t.has("colors"):
        raise t.fail("colors", 'only for kind = "mesh" (a mesh file\'s own colours)')
    placement = t.choice("placement", ["ground", "floating"], "ground")
    layout = t.choice("layout", ["random", "grid"], "random")
    M = L.MAX_COORDINATE
    o = ObjectSpec(
        kind=kind,
        path=path,
        files=files,
        count=t.int_range("count", 1, 0, L.MAX_INSTANCES) if layout == "random" else (0, 0),
        placement=placement,
        height=t.range("height", (0.5, 1.0) if placement == "floating" else 0.0, 0.0, M),
        layout=layout,
        x=t.range("x", 0.0, -M, M),
        z=t.range("z", 0.0, -M, M),
        grid=_grid(t) if layout == "grid" else (0, 0),
        spacing=_spacing(t) if layout == "grid" else (0.0, 0.0),
        fill=t.number("fill", 1.0, 0.0, 1.0) if layout == "grid" else 0.0,
        jitter=t.number("jitter", 0.0, 0.0, M) if layout == "grid" else 0.0,
        scale=t.range("scale", 1.0, 0.0, M, open_lo=True),
        stretch=_three(t.ranges("stretch", 1.0, 3, 1e-6, 1e6)),
        yaw=t.range("yaw", (0.0, 360.0), -3600.0, 3600.0),
        tilt=t.range("tilt", 0.0, -180.0, 180.0),
        albedo=t.color("albedo", 0.7),
        colors=colors,
    )
    if placement == "ground" and t.has("height"):
        raise t.fail("height", 'only for placement = "floating" (a grounded object rests at height 0)')
    if layout == "random":
        for key in ("grid", "spacing", "fill", "jitter"):
            if t.has(key):
                raise t.fail(key, 'only for layout = "grid"')
    elif t.has("count") or t.has("x") or t.has("z"):
        bad = next(k for k in ("count", "x", "z") if t.has(k))
        raise t.fail(bad, 'only for layout = "random" (a grid places one instance per cell)')
    t.done()
    return o


def _three(r: tuple[Range, ...]) -> tuple[Range, Range, Range]:
    return r[0], r[1], r[2]


def _grid(t: Table) -> tuple[int, int]:
    v = t.raw("grid", [1, 1])
    ok = (
        isinstance(v, list)
        and len(v) == 2
        and all(isinstance(x, int) and not isinstance(x, bool) and x >= 1 for x in v)
    )
    if not ok or v[0] * v[1] > L.MAX_INSTANCES:
        raise t.fail("grid", f"must be [nx, nz] positive integers with nx * nz <= {L.MAX_INSTANCES}, got {v!r}")
    return int(v[0]), int(v[1])


def _spacing(t: Table) -> tuple[float, float]:
    v = t.raw("spacing", 1.0)
    if not isinstance(v, list):
        v = [v, v]
    ok = isinstance(v, list) and len(v) == 2
    ok = ok and all(isinstance(x, (int, float)) and not isinstance(x, bool) and 0 < x <= L.MAX_COORDINATE for x in v)
    if not ok:
        raise t.fail("spacing", f"must be a number or [along x, along z], each in (0, {L.MAX_COORDINATE:g}], got {v!r}")
    return float(v[0]), float(v[1])


def _most_instances(o: ObjectSpec) -> int:
    return o.grid[0] * o.grid[1] if o.layout == "grid" else o.count[1]


def _file_kind(mode: int) -> str:
    for test, kind in (
        (stat.S_ISDIR, "folder"),
        (stat.S_ISCHR, "character device"),
        (stat.S_ISBLK, "block device"),
        (stat.S_ISFIFO, "FIFO"),
        (stat.S_ISSOCK, "socket"),
    ):
        if test(mode):
            return kind
    return "special file"


def _mesh_files(name: str, path: str, folder: str, colored: dict[str, bool], *, colors: bool) -> tuple[str, ...]:
    """The mesh files of ``path`` (a file or a folder of them), each read once
    (:func:`.build.check_mesh_file`): a file that cannot be used is refused
    now, naming it, rather than failing every item that draws it (with
    ``colors``, one whose colours cannot be used too). Only regular files:
    reading a device (``/dev/zero``) or a FIFO would never end. ``colored``
    gets whether each file carries colours."""
    if not path or "\x00" in path:
        raise SpecError(f"{name}: must be a mesh file or a folder of them, got {path!r}")
    full = os.path.normpath(os.path.join(folder, os.path.expanduser(path)))
    try:
        mode = os.stat(full).st_mode
    except FileNotFoundError:
        where = f"relative paths start at the spec's folder {folder!r}"
        raise SpecError(f"{name}: no such file or folder {path!r} ({where})") from None
    except OSError as e:
        raise SpecError(f"{name}: cannot read {path!r}: {e.strerror or e}") from None
    if stat.S_ISREG(mode):
        if os.path.splitext(full)[1].lower() not in MESH_EXTENSIONS:
            raise SpecError(f"{name}: {path!r} is not a mesh file; allowed extensions: {sorted(MESH_EXTENSIONS)}")
        found = [full]
    elif stat.S_ISDIR(mode):
        found = []
        for entry in sorted(os.listdir(full)):
            if os.path.splitext(entry)[1].lower() not in MESH_EXTENSIONS:
                continue
            f = os.path.join(full, entry)
            try:
                entry_mode = os.stat(f).st_mode
            except OSError as e:
                raise SpecError(f"{name}: {entry!r} in folder {path!r} cannot be read: {e.strerror or e}") from None
            if not stat.S_ISREG(entry_mode):
                kind = _file_kind(entry_mode)
                raise SpecError(f"{name}: {entry!r} in folder {path!r} is a {kind}, not a regular file")
            found.append(f)
            if len(found) > L.MAX_MESH_FILES:
                raise SpecError(f"{name}: {path!r} holds more than {L.MAX_MESH_FILES} mesh files")
        if not found:
            raise SpecError(f"{name}: folder {path!r} holds no mesh file ({sorted(MESH_EXTENSIONS)})")
    else:
        raise SpecError(f"{name}: {path!r} is a {_file_kind(mode)}, not a regular file or a folder of mesh files")
    for f in found:
        try:
            colored[f] = check_mesh_file(f, colors=colors)
        except MeshError as e:
            raise SpecError(f"{name}: {e}") from None
    return tuple(found)


def _light(t: Table) -> LightSpec:
    kind = t.choice("kind", LIGHT_KINDS)
    M = L.MAX_COORDINATE
    placed = kind in PLACED_KINDS
    for key, kinds in LIGHT_KEYS.items():
        if kind not in kinds and t.has(key):
            raise t.fail(key, f"only for kind = {_or(kinds)}")
    target = t.raw("target", [0.0, 0.0, 0.0]) if placed else [0.0, 0.0, 0.0]
    if not (
        isinstance(target, list)
        and len(target) == 3
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) and abs(x) <= M for x in target)
    ):
        raise t.fail("target", f"must be [x, y, z] finite numbers within [-{M:g}, {M:g}], got {target!r}")
    rect, round_ = kind == "rect", kind in ("disk", "sphere")
    light = LightSpec(
        kind=kind,
        weight=t.number("weight", 1.0, 0.0, M, open_lo=True),
        azimuth=t.range("azimuth", (0.0, 360.0), -3600.0, 3600.0),
        elevation=t.range("elevation", (30.0, 80.0), 1.0, 89.0)
        if placed
        else t.range("elevation", (20.0, 70.0), 1.0, 90.0),
        size=t.range("size", 1.0, 0.0, M, open_lo=True) if rect else (0.0, 0.0),
        aspect=t.range("aspect", 1.0, 1e-3, 1e3) if rect else (0.0, 0.0),
        distance=t.range("distance", (3.0, 5.0), 0.0, M, open_lo=True) if placed else (0.0, 0.0),
        target=(float(target[0]), float(target[1]), float(target[2])),
        angular_size=t.range("angular_size", 0.53, 0.0, 90.0) if not placed else (0.0, 0.0),
        power=t.range("radiance" if placed else "irradiance", 1.0, 0.0, M),
        radius=t.range("radius", 0.5, 0.0, M, open_lo=True) if round_ else (0.0, 0.0),
    )
    if kind == "sphere" and light.radius[1] >= light.distance[0]:
        raise t.fail(
            "radius",
            f"a sphere's radius must stay below its distance from the target (or the target is inside it): "
            f"radius up to {light.radius[1]:g}, distance from {light.distance[0]:g}",
        )
    t.done()
    return light


def _or(kinds: tuple[str, ...]) -> str:
    """``"rect"``, ``"disk" or "sphere"``, ``"rect", "disk" or "sphere"``."""
    quoted = [f'"{k}"' for k in kinds]
    return quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"


def _camera(t: Table) -> CameraSpec:
    M = L.MAX_COORDINATE
    res = t.raw("resolution", [640, 480])
    ok = (
        isinstance(res, list)
        and len(res) == 2
        and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= L.MAX_SIDE for x in res)
    )
    if not ok:
        raise t.fail("resolution", f"must be [width, height], integers in [1, {L.MAX_SIDE}], got {res!r}")
    c = CameraSpec(
        azimuth=t.range("azimuth", (0.0, 360.0), -3600.0, 3600.0),
        elevation=t.range("elevation", (15.0, 50.0), -89.0, 89.0),
        distance=t.range("distance", (4.0, 6.0), 0.0, M, open_lo=True),
        look_at_height=t.range("look_at_height", 0.3, -M, M),
        target_x=t.range("target_x", 0.0, -M, M),
        target_z=t.range("target_z", 0.0, -M, M),
        fov_y=t.range("fov_y", 40.0, 1.0, 170.0),
        resolution=(int(res[0]), int(res[1])),
    )
    t.done()
    return c


def _method(t: Table) -> MethodSpec:
    import softshadow as ss

    caps = ss.capabilities()
    name = t.choice("name", [*caps, REFERENCE], "auto")
    options_table = t.table("options")
    options = dict(options_table.value)
    options_table.read.update(options)
    mres = t.raw("map_resolution", None)
    if mres is not None:
        if isinstance(mres, int) and not isinstance(mres, bool):
            mres = [mres, mres]
        ok = (
            isinstance(mres, list)
            and len(mres) == 2
            and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= L.MAX_SIDE for x in mres)
        )
        if not ok:
            raise t.fail("map_resolution", f"must be an integer or [width, height] in [1, {L.MAX_SIDE}], got {mres!r}")
    m = MethodSpec(
        name=name,
        options=options,
        map_resolution=None if mres is None else (int(mres[0]), int(mres[1])),
        normal_offset=t.number("normal_offset", 0.0, 0.0, 1e3) if t.has("normal_offset") else None,
        depth_bias=t.number("depth_bias", 0.0, 0.0, 1e3) if t.has("depth_bias") else None,
        backend=t.choice("backend", ["cpu", "gpu", "auto"], "cpu"),
    )
    if name == REFERENCE:
        for key in ("map_resolution", "normal_offset", "depth_bias"):
            if t.has(key):
                raise t.fail(key, "not used by the Mitsuba reference")
        unknown = sorted(set(options) - {"samples"})
        if unknown:
            raise options_table.fail(unknown[0], "unknown option of 'reference'; allowed: samples")
        Table(options, options_table.path).integer("samples", 256, 1, ss.limits()["max_samples"])
        if importlib.util.find_spec("mitsuba") is None:
            raise t.fail("name", "'reference' needs Mitsuba 3: pip install softshadow[reference]")
    else:
        make_config(m, path=options_table.path)  # the core checks every option now
    t.done()
    return m


#: The lights a method's refusal is probed with (:func:`_check_light_kinds`):
#: one of each kind a map method may refuse, and a rectangle that every
#: method shades, over a box on a ground square.
_PROBE_LIGHTS = {
    "rect": ("RectLight", ((0.0, 3.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0))),
    "disk": ("DiskLight", ((0.0, 3.0, 0.0), (0.0, -1.0, 0.0), 0.5)),
    "sphere": ("SphereLight", ((0.0, 3.0, 0.0), 0.5)),
}


def _check_light_kinds(lights: tuple[LightSpec, ...], method: MethodSpec, light_maps: bool) -> None:
    """SpecError when the method cannot do with a kind of the spec's lights
    what every item drawing it would ask: shade it (naming ``method.name``:
    the map methods refuse spheres, ``smoothies`` disks too), or, with
    ``light_maps``, make its light-view maps (naming ``outputs.light_maps``:
    a sphere's shadows are traced).
    The core is asked, with a 4x4 render of a box under one light of that
    kind, as the items call it. Only disks and spheres are asked about
    (every method shades rectangles and the sun); a render the core refuses
    for a rectangle too is left to the items."""
    kinds = [k for k in ("disk", "sphere") if any(light.kind == k for light in lights)]
    if method.name == REFERENCE or not kinds:
        return
    import softshadow as ss

    from .._core import Auto
    from ..scenes.primitives import box, quad

    config: Any = make_config(method)
    loose: dict[str, Any] = {}
    if light_maps and config == Auto():
        config, loose = "auto", {"passes": 2}  # auto's map rule, as item.method_call runs it
    scene = ss.Scene(meshes=[box((0.0, 0.5, 0.0), (1.0, 1.0, 1.0)), quad((0.0, 0.0, 0.0), 2.0)])
    camera = ss.Camera.look_at(
        eye=(3.0, 3.0, 3.0), target=(0.0, 0.3, 0.0), up=(0.0, 1.0, 0.0), fov_y=40.0, resolution=(4, 4)
    )

    def probe(kind: str) -> tuple[str | None, bool]:
        """(the core's refusal or None, whether it made light-view maps)."""
        cls, args = _PROBE_LIGHTS[kind]
        try:
            img = ss.render(
                scene, getattr(ss, cls)(*args), camera, config, map_resolution=(8, 8),
                normal_offset=method.normal_offset, depth_bias=method.depth_bias, threads=1, **loose,
            )  # fmt: skip
        except ValueError as e:
            return str(e), False
        return None, bool(img.shadow_maps)

    rect = probe("rect")
    if rect[0] is not None:
        return  # not about the kind: the items will say what it is
    for kind in kinds:
        i = next(i for i, light in enumerate(lights) if light.kind == kind)
        why, maps = probe(kind)
        if why is not None:
            raise SpecError(
                f"method.name: {method.name!r} cannot shade lights[{i}], of kind = {kind!r} ({why}); "
                '"exact" and "auto" shade every kind'
            )
        if light_maps and rect[1] and not maps:
            raise SpecError(
                f"outputs.light_maps: method {method.name!r} makes no light-view maps for lights[{i}], "
                f"of kind = {kind!r} (its shadows are traced)"
            )


def make_config(m: MethodSpec, *, path: str = "method.options") -> Any:
    """The method's typed config from its name and options. An option whose
    value is a table ``{ type = "SlopeScaleBias", ... }`` becomes that config
    (the nested configs of ``shadow_mapping``)."""
    import softshadow as ss

    info = ss.capabilities()[m.name]
    kwargs: dict[str, Any] = {}
    for key, value in m.options.items():
        if key not in info.options:
            raise SpecError(f"{path}.{key}: unknown option of {m.name!r}; allowed: {', '.join(info.options)}")
        kwargs[key] = _option_value(f"{path}.{key}", value, info.options[key])
    try:
        return info.config(**kwargs)
    except (TypeError, ValueError) as e:
        raise SpecError(f"{path}.{e}" if str(e).split(":")[0] in kwargs else f"{path}: {e}") from e


def _option_value(name: str, value: Any, option: Any) -> Any:
    import softshadow as ss

    if isinstance(value, dict):
        kinds = option.choices or []
        kind = value.get("type")
        if option.kind != "config" or not isinstance(kind, str) or kind not in kinds:
            raise SpecError(f"{name}: a table needs type = one of {kinds}, got {kind!r}")
        rest = {k: v for k, v in value.items() if k != "type"}
        try:
            return getattr(ss, kind)(**rest)
        except (TypeError, ValueError) as e:
            raise SpecError(f"{name}: {e}") from e
    if isinstance(value, list):
        return tuple(value)
    return value


def _outputs(t: Table, method: MethodSpec, lights: tuple[LightSpec, ...], lights_per_item: IntRange) -> OutputSpec:
    shading = shading_available() and method.name != REFERENCE
    available = [c for c in CHANNELS if shading or c not in SHADING_CHANNELS]
    default = [c for c in DEFAULT_CHANNELS if c in available]
    channels = t.raw("channels", default)
    if not isinstance(channels, list) or not channels or not all(isinstance(c, str) for c in channels):
        raise t.fail("channels", f"must be a non-empty list of channel names from {CHANNELS}, got {channels!r}")
    for c in channels:
        if c not in CHANNELS:
            raise t.fail("channels", f"unknown channel {c!r}; allowed: {CHANNELS}")
        if c not in available:
            why = (
                "the Mitsuba reference gives visibility only"
                if method.name == REFERENCE
                else ("this softshadow's render does not shade")
            )
            raise t.fail("channels", f"{c!r} is not available ({why}); available: {available}")
    if len(set(channels)) != len(channels):
        raise t.fail("channels", f"lists a channel twice: {channels!r}")
    light_maps = t.boolean("light_maps", False)
    if light_maps and (method.name in ("exact", REFERENCE)):
        raise t.fail("light_maps", f"method {method.name!r} makes no light-view maps")
    if light_maps:
        fixed = method.map_resolution is not None or "occluder_resolution" in method.options
        if lights_per_item[1] > 1 and not fixed:
            raise t.fail(
                "light_maps",
                "with several lights per item every light's maps go to one EXR file, so they need one size: "
                "set method.map_resolution",
            )
    folder = t.string("folder", "items")
    if len(folder) > L.MAX_NAME or not FOLDER_NAME.match(folder) or folder in RESERVED_NAMES:
        raise t.fail(
            "folder",
            f"must be one plain folder name inside --out (letters, digits, '_', '-', '.'; not starting with '.'; "
            f"at most {L.MAX_NAME} characters; not one of {sorted(RESERVED_NAMES)}), got {folder!r}",
        )
    compression = t.string("compression", "zip")
    try:
        exr_compression(compression)
    except ValueError as e:
        raise t.fail("compression", str(e).removeprefix("compression: ")) from None
    except ImportError:
        pass  # no OpenEXR: writing the first item says so
    o = OutputSpec(tuple(channels), light_maps, t.boolean("previews", False), folder, compression)
    t.done()
    return o
