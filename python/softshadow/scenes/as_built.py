"""Eye-view scenes built the way users build them: floors, walls and tables
as closed boxes, furniture of thin panels, objects resting on, touching and
intersecting each other, open meshes with flipped and degenerate faces,
multi-part files loaded through ``trimesh.load``, many meshes and 100 000+
triangles, rectangle lights large and small, near and far, the sun high and
at 10 degrees. Each builder returns ``(scene, light, camera)`` at the
resolution asked for.

The scenes come in two sets (docs/accuracy.md):

* :data:`CALIBRATION`: the scenes any rule, threshold or constant of the
  library may be fitted to;
* :data:`HELD_OUT`: scenes nothing is fitted to; they judge what was fitted
  on the others. Do not look at them while tuning.

The teapot and the two asset files need ``trimesh`` (``pip install
softshadow[io]``); the other scenes are numpy only. Meshes: the Stanford
bunny, Blender's Suzanne and the Utah teapot from the trimesh project's
models (see ``softshadow/data/README.md``).
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import resources

import numpy as np

from ..lights import DirectionalLight, RectLight
from ..scene import Camera, Mesh, Scene
from .primitives import box, bunny_mesh, rotated, sphere, torus

EyeScene = tuple[Scene, RectLight | DirectionalLight, Camera]

__all__ = ["CALIBRATION", "HELD_OUT", "SCENES", "EyeScene"]


# --------------------------------------------------------------------------
# Parts as users make them
# --------------------------------------------------------------------------


def slab(top: float = 0.0, half: float = 4.0, thickness: float = 0.1) -> Mesh:
    """A floor as a closed box whose top face is at ``top``."""
    return box((0.0, top - thickness / 2, 0.0), (2 * half, thickness, 2 * half))


def moved(mesh: Mesh, offset: tuple[float, float, float]) -> Mesh:
    v, f = mesh
    return v + np.asarray(offset, dtype=np.float64), f


def scaled(mesh: Mesh, s: float, about: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Mesh:
    v, f = mesh
    o = np.asarray(about, dtype=np.float64)
    return (v - o) * s + o, f


def _bundled(name: str) -> Mesh:
    with resources.files("softshadow").joinpath(f"data/{name}.npz").open("rb") as f:
        data = np.load(f)
        return data["vertices"].astype(np.float64), data["faces"].astype(np.uint32)


def _standing(mesh: Mesh, size: float, up_axis: int = 1) -> Mesh:
    """``mesh`` turned y-up, scaled to ``size`` at its widest, centred over
    the origin in x and z, standing on y = 0."""
    v, f = mesh
    if up_axis == 2:
        v = v[:, [0, 2, 1]] * np.array([1.0, 1.0, -1.0])
    lo, hi = v.min(axis=0), v.max(axis=0)
    v = (v - 0.5 * (lo + hi)) * (size / float((hi - lo).max()))
    v[:, 1] -= v[:, 1].min()
    return v, f


def suzanne(size: float = 0.6) -> Mesh:
    """Blender's Suzanne: open (eyes apart from the head), 968 triangles."""
    return _standing(_bundled("suzanne"), size)


def teapot(size: float = 0.6) -> Mesh:
    """The Utah teapot as its STL file holds it: a triangle soup (no vertex
    shared between triangles), open at the spout and lid."""
    return _standing(_bundled("teapot"), size, up_axis=2)


def damaged(mesh: Mesh, seed: int, flip: float = 0.3, degenerate: int = 40) -> Mesh:
    """``mesh`` with a fraction ``flip`` of its faces wound the other way and
    ``degenerate`` zero-area triangles (repeated vertices, collinear ones)
    added: what an exported asset often holds."""
    v, f = mesh
    rng = np.random.default_rng(seed)
    f = f.copy()
    turn = rng.random(len(f)) < flip
    f[turn] = f[turn][:, ::-1]
    picks = rng.integers(0, len(v), size=(degenerate, 2))
    repeated = np.stack([picks[:, 0], picks[:, 0], picks[:, 1]], axis=1)
    mid = (v[picks[:, 0]] + v[picks[:, 1]]) / 2
    v2 = np.vstack([v, mid])
    collinear = np.stack([picks[:, 0], len(v) + np.arange(degenerate), picks[:, 1]], axis=1)
    return v2, np.vstack([f, repeated, collinear]).astype(np.uint32)


def table(center: tuple[float, float, float], size: tuple[float, float, float], top: float = 0.05) -> list[Mesh]:
    """A table of closed boxes: a top ``top`` thick and four legs; ``size``
    is its full (width, height, depth), ``center`` the middle of its foot
    print on the floor."""
    cx, cy, cz = center
    w, h, d = size
    leg = 0.06
    parts = [box((cx, cy + h - top / 2, cz), (w, top, d))]
    for sx in (-1, 1):
        for sz in (-1, 1):
            parts.append(
                box((cx + sx * (w / 2 - leg), cy + (h - top) / 2, cz + sz * (d / 2 - leg)), (leg, h - top, leg))
            )
    return parts


def chair(center: tuple[float, float, float], facing: float) -> list[Mesh]:
    """A chair of thin panels (seat, back, legs), turned ``facing`` degrees
    about y."""
    cx, cy, cz = center
    parts = [box((0.0, 0.45, 0.0), (0.45, 0.03, 0.45)), box((0.0, 0.75, -0.21), (0.45, 0.6, 0.03))]
    for sx in (-1, 1):
        for sz in (-1, 1):
            parts.append(box((sx * 0.19, 0.22, sz * 0.19), (0.04, 0.44, 0.04)))
    out = []
    for p in parts:
        v, f = rotated(p, facing, "y", about=(0.0, 0.0, 0.0))
        out.append((v + np.array([cx, cy, cz]), f))
    return out


def shelf(center: tuple[float, float, float], shelves: int = 4) -> list[Mesh]:
    """A bookcase of 2 cm panels: two sides, a back, a top, ``shelves``
    boards; 0.9 wide, 1.8 tall, 0.35 deep."""
    cx, cy, cz = center
    t, w, h, d = 0.02, 0.9, 1.8, 0.35
    parts = [
        box((cx - w / 2 + t / 2, cy + h / 2, cz), (t, h, d)),
        box((cx + w / 2 - t / 2, cy + h / 2, cz), (t, h, d)),
        box((cx, cy + h / 2, cz - d / 2 + t / 2), (w, h, t)),
        box((cx, cy + h - t / 2, cz), (w, t, d)),
    ]
    for k in range(shelves):
        y = cy + 0.05 + k * (h - 0.1) / shelves
        parts.append(box((cx, y, cz), (w - 2 * t, t, d - t)))
    return parts


def sun_at(elevation: float, azimuth: float, size: float = 0.53) -> DirectionalLight:
    """The sun ``elevation`` degrees above the horizon, coming from
    ``azimuth`` degrees about y (0: from +x)."""
    e, a = np.deg2rad(elevation), np.deg2rad(azimuth)
    d = (-np.cos(e) * np.cos(a), -np.sin(e), -np.cos(e) * np.sin(a))
    return DirectionalLight(direction=d, up=(0.0, 1.0, 0.0), angular_size=(size, size))


def rect_light(
    center: tuple[float, float, float], target: tuple[float, float, float], size: tuple[float, float]
) -> RectLight:
    """A rectangle light at ``center`` facing ``target``."""
    n = np.asarray(target, dtype=np.float64) - np.asarray(center, dtype=np.float64)
    up = (0.0, 0.0, 1.0) if abs(n[1]) > 0.9 * np.linalg.norm(n) else (0.0, 1.0, 0.0)
    return RectLight(center=center, normal=tuple(n), up=up, size=size)


def _camera(
    eye: tuple[float, float, float], target: tuple[float, float, float], resolution: tuple[int, int], fov: float = 40.0
) -> Camera:
    return Camera.look_at(eye=eye, target=target, up=(0.0, 1.0, 0.0), fov_y=fov, resolution=resolution)


def _from_file(name: str) -> list[Mesh]:
    """Every mesh of a bundled asset as ``trimesh.load`` reads it, node
    transforms applied (:meth:`softshadow.Scene.from_trimesh`)."""
    with resources.as_file(resources.files("softshadow").joinpath(f"data/{name}")) as path:
        return Scene.from_trimesh(path).meshes


# --------------------------------------------------------------------------
# Calibration scenes
# --------------------------------------------------------------------------


def bunny_on_slab(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """The bunny on a floor made of a 10 cm box, a 1 x 1 light to its side."""
    scene = Scene(meshes=[bunny_mesh(1.0, 0.0), slab()])
    light = rect_light((1.5, 3.5, 1.0), (0.0, 0.0, 0.0), (1.0, 1.0))
    return scene, light, _camera((2.2, 1.6, 2.8), (0.0, 0.4, 0.0), resolution, 35.0)


def blocks_on_table(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Blocks touching each other on a box table, a 2 x 1 light above."""
    meshes = [slab(), *table((0.0, 0.0, 0.0), (1.6, 0.75, 1.0))]
    meshes += [
        box((-0.3, 0.75 + 0.15, 0.0), (0.3, 0.3, 0.3)),
        box((0.0, 0.75 + 0.1, 0.05), (0.3, 0.2, 0.3)),  # touches the first
        rotated(box((0.35, 0.75 + 0.2, -0.1), (0.15, 0.4, 0.15)), 25.0, "y"),
        sphere((0.3, 0.75 + 0.12, 0.25), 0.12),
    ]
    light = rect_light((0.3, 2.4, 0.6), (0.0, 0.75, 0.0), (2.0, 1.0))
    return Scene(meshes=meshes), light, _camera((1.6, 1.9, 2.2), (0.0, 0.7, 0.0), resolution)


def torus_on_slab(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A tilted torus shadowing its own far side, over a box floor."""
    ring = rotated(torus((0.0, 0.9, 0.0), 0.6, 0.22), 55.0, "x", about=(0.0, 0.9, 0.0))
    light = rect_light((0.3, 4.0, 0.8), (0.0, 0.0, 0.0), (0.8, 0.8))
    return Scene(meshes=[ring, slab()]), light, _camera((2.4, 1.9, 2.2), (0.0, 0.7, 0.0), resolution, 38.0)


def room_window(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A closed room of box walls (4 x 2.5 x 4) lit by a window-sized light
    in one wall, a table and a sphere inside, the camera in the room."""
    t = 0.15
    walls = [
        slab(0.0, 2.0 + t, t),
        box((0.0, 2.5 + t / 2, 0.0), (4 + 2 * t, t, 4 + 2 * t)),  # ceiling
        box((-2.0 - t / 2, 1.25, 0.0), (t, 2.5, 4.0)),
        box((2.0 + t / 2, 1.25, 0.0), (t, 2.5, 4.0)),
        box((0.0, 1.25, -2.0 - t / 2), (4.0, 2.5, t)),
        box((0.0, 1.25, 2.0 + t / 2), (4.0, 2.5, t)),
    ]
    furniture = [*table((0.3, 0.0, -0.4), (1.2, 0.72, 0.8)), sphere((-0.6, 0.3, 0.4), 0.3)]
    # The window: a 1.2 x 0.8 light 5 cm inside the -x wall, facing into the room.
    light = RectLight(center=(-1.95, 1.6, -0.2), normal=(1.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), size=(1.2, 0.8))
    return Scene(meshes=walls + furniture), light, _camera((1.8, 1.6, 1.8), (-0.2, 0.5, -0.4), resolution, 60.0)


def shelf_with_objects(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A bookcase of thin panels holding small boxes and spheres, on a box
    floor against a box wall, lit from the front and above."""
    meshes = [slab(), box((0.0, 1.2, -0.3), (4.0, 2.4, 0.1)), *shelf((0.0, 0.0, 0.0))]
    rng = np.random.default_rng(3)
    for k in range(4):
        y = 0.05 + k * 1.7 / 4 + 0.01
        for x in np.linspace(-0.3, 0.3, 3):
            s = float(rng.uniform(0.06, 0.14))
            if rng.random() < 0.5:
                meshes.append(box((x, y + s / 2, 0.0), (s, s, s)))
            else:
                meshes.append(sphere((x, y + s / 2, 0.02), s / 2, n=24))
    light = rect_light((0.6, 2.6, 1.8), (0.0, 0.8, 0.0), (0.8, 0.8))
    return Scene(meshes=meshes), light, _camera((1.2, 1.3, 2.4), (0.0, 0.85, 0.0), resolution, 45.0)


def open_assets(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Suzanne and the teapot (open meshes, a triangle soup) with flipped
    faces and degenerate triangles, on a box floor."""
    meshes = [
        slab(),
        moved(damaged(suzanne(0.7), seed=1), (-0.45, 0.0, 0.0)),
        moved(damaged(teapot(0.7), seed=2), (0.45, 0.0, 0.1)),
    ]
    light = rect_light((1.0, 2.5, 1.5), (0.0, 0.0, 0.0), (0.7, 0.7))
    return Scene(meshes=meshes), light, _camera((0.4, 1.2, 2.2), (0.0, 0.25, 0.0), resolution)


def spheres_sun_high(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """64 finely tessellated spheres (145 000 triangles) on a box floor, the
    sun 60 degrees up."""
    meshes = [slab(0.0, 6.0)]
    rng = np.random.default_rng(5)
    for i in range(8):
        for j in range(8):
            r = float(rng.uniform(0.12, 0.3))
            meshes.append(sphere((-2.8 + 0.8 * i, r * float(rng.uniform(0.6, 1.0)), -2.8 + 0.8 * j), r, n=48))
    return Scene(meshes=meshes), sun_at(60.0, 30.0), _camera((4.0, 3.5, 4.5), (0.0, 0.0, 0.0), resolution)


def stairs_low_sun(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A stair of box steps and pillars on a box floor, the sun 10 degrees
    above the horizon."""
    meshes = [slab(0.0, 6.0)]
    for k in range(8):
        meshes.append(box((0.0, 0.1 * (k + 1) / 2, -0.3 * k), (1.5, 0.1 * (k + 1), 0.3)))
    for x in (-1.2, 1.2):
        meshes.append(box((x, 0.6, -1.0), (0.2, 1.2, 0.2)))
    return Scene(meshes=meshes), sun_at(10.0, -20.0), _camera((3.0, 2.0, 3.0), (0.0, 0.3, -1.0), resolution)


# --------------------------------------------------------------------------
# Held-out scenes: nothing is fitted to these
# --------------------------------------------------------------------------


def bunnies_intersecting(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Two bunnies passing through each other on a box, a small light far up."""
    a = bunny_mesh(0.8, 0.3)
    b = rotated(moved(bunny_mesh(0.7, 0.3), (0.25, 0.0, 0.1)), 70.0, "y")
    meshes = [slab(), box((0.0, 0.15, 0.0), (1.2, 0.3, 1.0)), a, b]
    light = rect_light((2.0, 6.0, 1.0), (0.0, 0.0, 0.0), (0.3, 0.3))
    return Scene(meshes=meshes), light, _camera((1.8, 1.5, 2.2), (0.0, 0.5, 0.0), resolution)


def table_and_chairs(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A table and two chairs of thin panels, a 3 x 3 light close above."""
    meshes = [slab(), *table((0.0, 0.0, 0.0), (1.4, 0.74, 0.9))]
    meshes += chair((0.0, 0.0, 0.75), 180.0) + chair((-0.95, 0.0, 0.0), 90.0)
    light = rect_light((0.2, 2.3, 0.1), (0.2, 0.0, 0.1), (3.0, 3.0))
    return Scene(meshes=meshes), light, _camera((2.0, 1.7, 2.4), (-0.2, 0.4, 0.1), resolution)


def still_life_obj(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """An OBJ of several objects (Suzanne, the teapot, a cup) as
    ``trimesh.load`` returns it (one merged mesh), on a box table top."""
    meshes = [slab(), *table((0.0, 0.0, 0.0), (1.6, 0.7, 1.2))]
    meshes += [moved(m, (0.0, 0.7, 0.0)) for m in _from_file("still_life.obj")]
    light = rect_light((-1.0, 2.2, 1.2), (0.0, 0.7, 0.0), (0.6, 0.4))
    return Scene(meshes=meshes), light, _camera((1.4, 1.5, 1.6), (0.0, 0.8, 0.0), resolution)


def suzannes_glb(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A glTF whose nodes place one Suzanne three times and a teapot, on a
    box floor, the sun 35 degrees up."""
    meshes = [slab(), *_from_file("suzannes.glb")]
    return Scene(meshes=meshes), sun_at(35.0, 120.0), _camera((0.2, 1.3, 2.3), (0.0, 0.2, 0.0), resolution)


def fence_slats(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """A fence of 2 cm slats (closed boxes, 4 cm apart) on rails, a wide low
    light close behind it."""
    meshes = [slab()]
    for k in range(25):
        meshes.append(box((-1.2 + 0.1 * k, 0.5, 0.0), (0.02, 1.0, 0.02)))
    meshes += [box((0.0, 0.2, -0.03), (2.6, 0.06, 0.03)), box((0.0, 0.8, -0.03), (2.6, 0.06, 0.03))]
    light = rect_light((0.0, 1.6, -1.2), (0.0, 0.0, 1.0), (1.5, 0.5))
    return Scene(meshes=meshes), light, _camera((1.5, 1.4, 2.4), (0.0, 0.3, 0.6), resolution)


def courtyard_low_sun(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Walls around a court and a ring of columns (open cylinders), the sun
    10 degrees up."""
    meshes = [slab(0.0, 8.0)]
    for x, z, w, d in ((0.0, -3.0, 6.0, 0.3), (0.0, 3.0, 6.0, 0.3), (-3.0, 0.0, 0.3, 6.0)):
        meshes.append(box((x, 0.75, z), (w, 1.5, d)))
    for k in range(10):
        a = 2 * np.pi * k / 10
        meshes.append(_cylinder((1.6 * np.cos(a), 0.0, 1.6 * np.sin(a)), 0.12, 1.8))
    return Scene(meshes=meshes), sun_at(10.0, 15.0), _camera((5.0, 3.0, 4.0), (0.0, 0.5, 0.0), resolution)


def crowd(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """60 objects (bunnies, tori, spheres, boxes; 330 000 triangles) on a box
    floor, a small light far up."""
    meshes = [slab(0.0, 5.0)]
    rng = np.random.default_rng(9)
    bunny = bunny_mesh(0.5, 0.0)
    for k in range(60):
        x, z = float(rng.uniform(-3.0, 3.0)), float(rng.uniform(-3.0, 3.0))
        kind = k % 4
        if kind == 0:
            meshes.append(rotated(moved(bunny, (x, 0.0, z)), float(rng.uniform(0, 360)), "y"))
        elif kind == 1:
            meshes.append(torus((x, 0.08, z), 0.2, 0.08, 48, 24))
        elif kind == 2:
            meshes.append(sphere((x, 0.2, z), 0.2, n=64))
        else:
            meshes.append(rotated(box((x, 0.15, z), (0.3, 0.3, 0.3)), float(rng.uniform(0, 90)), "y"))
    light = rect_light((3.0, 8.0, 2.0), (0.0, 0.0, 0.0), (0.5, 0.5))
    return Scene(meshes=meshes), light, _camera((5.0, 4.0, 5.0), (0.0, 0.0, 0.0), resolution)


def blinds(resolution: tuple[int, int] = (640, 480)) -> EyeScene:
    """Horizontal slats of a blind (thin boxes, tilted) between a light and
    a box floor with a chair on it."""
    meshes = [slab(), *chair((0.3, 0.0, 0.2), 30.0)]
    for k in range(12):
        slat = box((0.0, 1.6, -1.1 + 0.2 * k), (2.0, 0.01, 0.12))
        meshes.append(rotated(slat, 35.0, "x"))
    light = rect_light((0.0, 2.6, 0.0), (0.0, 0.0, 0.0), (1.6, 1.6))
    return Scene(meshes=meshes), light, _camera((1.9, 1.2, 2.3), (0.0, 0.4, 0.0), resolution)


def _cylinder(base: tuple[float, float, float], radius: float, height: float, n: int = 32) -> Mesh:
    """An open tube (no caps) standing on ``base``."""
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = np.stack([radius * np.cos(a), np.zeros(n), radius * np.sin(a)], axis=1)
    v = np.vstack([ring, ring + [0.0, height, 0.0]]) + np.asarray(base, dtype=np.float64)
    i = np.arange(n)
    j = (i + 1) % n
    f = np.concatenate([np.stack([i, j + n, j], 1), np.stack([i, i + n, j + n], 1)])
    return v, f.astype(np.uint32)


#: Scenes rules and constants may be fitted to.
CALIBRATION: dict[str, Callable[..., EyeScene]] = {
    "bunny_on_slab": bunny_on_slab,
    "blocks_on_table": blocks_on_table,
    "torus_on_slab": torus_on_slab,
    "room_window": room_window,
    "shelf_with_objects": shelf_with_objects,
    "open_assets": open_assets,
    "spheres_sun_high": spheres_sun_high,
    "stairs_low_sun": stairs_low_sun,
}

#: Scenes nothing is fitted to: they judge what was.
HELD_OUT: dict[str, Callable[..., EyeScene]] = {
    "bunnies_intersecting": bunnies_intersecting,
    "table_and_chairs": table_and_chairs,
    "still_life_obj": still_life_obj,
    "suzannes_glb": suzannes_glb,
    "fence_slats": fence_slats,
    "courtyard_low_sun": courtyard_low_sun,
    "crowd": crowd,
    "blinds": blinds,
}

#: Both sets.
SCENES: dict[str, Callable[..., EyeScene]] = {**CALIBRATION, **HELD_OUT}
