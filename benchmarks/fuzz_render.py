"""Fuzzes the eye-view entry `softshadow.render` (and `soft_shadow_map` from
meshes, where cheap) with scenes as users build them (not part of CI; a brief
run is tests/api/test_fuzz_render.py).

Each call is drawn from a seeded numpy Generator (`default_rng([seed, i])`,
so call i of a seed is the same call on every run and `--replay i` repeats
it): trimesh boxes as floors, walls and closed rooms (inverted or not), thin
and zero-thickness panels, spheres, capsules, cylinders and triangle soups,
touching, intersecting and sunk into each other; flipped meshes (faces
reversed), open ones (faces removed), degenerate and duplicated triangles,
far unreferenced vertices, float32/int64/list/Fortran arrays; the scene scaled
by 1e-6 to 1e6 and moved up to 1e7 from the origin. A RectLight (sizes from
0 to huge, anisotropic, behind or inside the geometry) or a DirectionalLight
(0 to 179 degrees, scalar or (a, b)); a Camera.look_at up to 640x480, at times
inside a box or degenerate (eye == target, up along the view, fov 0 or
179.9); a method (the names with their loose options, the typed configs with
options from `capabilities()`, ShadowMapping with its parts, Auto with
targets) and keywords (map_resolution up to 8192, biases, threads, backend,
albedo, estimate_error). About six calls in ten draw only valid values, so
that most reach the kernels; the others draw hostile ones (0, negatives,
NaN, inf, 2**64, wrong types, NaN vertices, faces out of range, ...) with a
per-call rate. One call in four also maps the scene with `soft_shadow_map`
(the scene itself or split into occluders and receivers), and some
successful renders are repeated on the same Scene (its kept preparation)
with threads=1, which must give the same bits.

Every library step (Scene, the light, the camera, render, soft_shadow_map)
must either return -- an Image of the camera's shape whose visibility is
finite and in [0, 1] (1 where no surface), shaded and unshadowed finite,
>= 0, 0 where no surface and shaded = unshadowed * visibility, depth inf /
position NaN / normal 0 / mesh_id -1 exactly where no surface (finite, unit
normals where one), 0 behind a RectLight's plane, a resolved method and a
finite error estimate; a ShadowMap with a finite visibility in [0, 1], 1
where no receiver -- or raise ValueError, TypeError, MemoryError (TooLargeError
included) or, for backend="gpu", GpuUnavailableError, whose message starts
with an argument's name and ':' ("backend: ...", "max_taps: ..."). Anything
else fails: another exception (RuntimeError "internal error" is a Rust
panic), an unnamed message, a wrong output, a step over 60 s, a step whose
peak memory (VmHWM, reset before each step through /proc/self/clear_refs)
passes 4 GiB, a crash (abort, segfault) or a hang.

The calls run in a worker process, one after the other, watched by this one:
a worker that dies or stays silent for `--hang` seconds is reported with the
call it was running and replaced by a fresh one at the next call. The worker
gets SOFTSHADOW_MEMORY_LIMIT=2 GiB (unless the environment sets it), so the
library refuses with TooLargeError what its accounting says would not fit in
2 GiB; the 4 GiB bound then catches memory the accounting misses (Rust
aborts on a failed allocation, so an unbounded request would end the worker
instead). The summary gives the calls, the outcomes per step, the arguments
refusals named, the slowest steps with their calls, the peak memory, and
every distinct failure with a Python snippet that reproduces it; the exit
status is 1 on any failure.

    python benchmarks/fuzz_render.py --minutes 10             # as recorded in docs/development.md
    python benchmarks/fuzz_render.py --calls 500 --seed 3     # a fixed budget instead
    python benchmarks/fuzz_render.py --seed 3 --replay 123    # call 123 of seed 3: its snippet, run here
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import os
import re
import select
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import softshadow as ss

GIB = 1 << 30
#: A step slower than this fails (seconds), as does one whose peak RSS passes MEMORY_FAIL.
SLOW_S = 60.0
MEMORY_FAIL = 4 * GIB
#: What the worker's library may allocate (SOFTSHADOW_MEMORY_LIMIT) unless the environment says.
MEMORY_LIMIT = 2 * GIB
#: Share of calls that draw only valid values; the others draw hostile ones at a per-call rate.
CLEAN = 0.6
HEADER = "import numpy as np, trimesh, softshadow as ss"

ALLOWED = (ValueError, TypeError, MemoryError)
#: Names a refusal may start with: every argument of the calls drawn, the
#: methods' options and what the checks name inside them.
KNOWN_NAMES = {
    # render, soft_shadow_map
    "scene",
    "light",
    "camera",
    "method",
    "map_resolution",
    "normal_offset",
    "depth_bias",
    "passes",
    "samples",
    "occluder_resolution",
    "hierarchy",
    "precision",
    "backend",
    "threads",
    "albedo",
    "estimate_error",
    "resolution",
    "extent",
    # Scene and its meshes
    "meshes",
    "occluders",
    "receivers",
    "vertices",
    "faces",
    # the lights, the camera
    "center",
    "normal",
    "up",
    "size",
    "radiance",
    "direction",
    "angular_size",
    "irradiance",
    "eye",
    "target",
    "fov_y",
    # the configs' parts
    "bias",
    "filter",
    "warp",
    "focus",
    "blur",
    "constant",
    "slope",
    "iterations",
    "radius",
    "vector",
    "n",
    "error",
    "time",
}
for _info in ss.methods.capabilities().values():
    KNOWN_NAMES.update(_info.options)
NAMED = re.compile(r"^([A-Za-z_]\w*)(\[[^\]]*\]|\.\w+)*$")


# --------------------------------------------------------------------------
# Drawing a call: Python source, so that the reproducer is what ran
# --------------------------------------------------------------------------


class Code(str):
    """Source text, written as is by `lit`."""


def lit(v: Any) -> str:
    """`v` as Python source."""
    if isinstance(v, Code):
        return str(v)
    if v is None or isinstance(v, bool):
        return repr(v)
    if isinstance(v, (int, np.integer)):
        return repr(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if math.isnan(v):
            return "float('nan')"
        if math.isinf(v):
            return "float('inf')" if v > 0 else "-float('inf')"
        return repr(v)
    if isinstance(v, tuple):
        inner = ", ".join(lit(x) for x in v)
        return f"({inner},)" if len(v) == 1 else f"({inner})"
    if isinstance(v, list):
        return "[" + ", ".join(lit(x) for x in v) + "]"
    if isinstance(v, (str, bytes)):
        return repr(v)
    raise TypeError(f"no literal for {type(v).__name__}")


def call(fn: str, *args: Any, **kw: Any) -> str:
    parts = [lit(a) for a in args] + [f"{k}={lit(v)}" for k, v in kw.items()]
    return f"{fn}({', '.join(parts)})"


def g(x: float) -> float:
    """Four significant digits: short snippets, exact values."""
    return float(f"{x:.4g}")


HOSTILE_INT = ["0", "-1", "2**31", "2**64", "1.5", "float('nan')", "'16'", "[16]", "b'16'"]
HOSTILE_FLOAT = ["-1.0", "float('nan')", "float('inf')", "-float('inf')", "1e300", "'0.5'", "[0.5]", "1j"]
HOSTILE_RES = [
    "0",
    "-1",
    "(0, 64)",
    "(-1, 64)",
    "1 << 20",
    "(1 << 16, 1 << 16)",
    "64.5",
    "'64'",
    "(64, 64, 64)",
    "(64,)",
]
HOSTILE_CHOICE = ["'bogus'", "''", "3", "b'x'", "['f32']"]
HOSTILE_BOOL = ["1", "'yes'", "2.0"]
HOSTILE_VEC = ["(float('nan'), 0.0, 1.0)", "(0.0, 0.0, 0.0)", "(1.0, 2.0)", "'up'", "(float('inf'), 1.0, 0.0)"]


class Draw:
    def __init__(self, seed: int, index: int) -> None:
        self.rng = np.random.default_rng([seed, index])
        self.rate = 0.0 if self.rng.random() < CLEAN else float(self.choice([0.05, 0.1, 0.2, 0.4]))
        self.hostile_args: list[str] = []

    def coin(self, p: float) -> bool:
        return bool(self.rng.random() < p)

    def hostile(self, name: str) -> bool:
        if self.rate and self.coin(self.rate):
            self.hostile_args.append(name)
            return True
        return False

    def choice(self, seq: list | tuple) -> Any:
        return seq[int(self.rng.integers(len(seq)))]

    def uniform(self, a: float, b: float) -> float:
        return g(float(self.rng.uniform(a, b)))

    def logu(self, a: float, b: float) -> float:
        return g(float(np.exp(self.rng.uniform(np.log(a), np.log(b)))))

    def int(self, a: int, b: int) -> int:
        """In [a, b]."""
        return int(self.rng.integers(a, b + 1))

    def unit(self) -> np.ndarray:
        v = self.rng.normal(size=3)
        return v / np.linalg.norm(v)


@dataclass
class Mesh:
    var: str
    role: str  # floor, wall, room, object
    trimesh: bool  # a trimesh.Trimesh (else a (vertices, faces) pair)
    pos: tuple[float, float, float]
    half: float  # about half its size


@dataclass
class Case:
    seed: int
    index: int
    setup: list[str]  # the meshes, made with numpy and trimesh (not the library's)
    steps: list[tuple[str, str]]  # (name, source), run in order
    label: str
    gpu: bool = False  # some step asks for backend="gpu" (GpuUnavailableError allowed)
    repeat: bool = False  # the "repeat" step must give the render's bits
    hostile: list[str] = field(default_factory=list)

    def snippet(self, upto: str | None = None) -> str:
        lines = [HEADER, *self.setup]
        for name, src in self.steps:
            lines.append(src)
            if name == upto:
                break
        return "\n".join(lines)


def vf(m: Mesh) -> tuple[str, str]:
    return (f"{m.var}.vertices", f"{m.var}.faces") if m.trimesh else (f"{m.var}[0]", f"{m.var}[1]")


def draw_object(d: Draw, var: str, lines: list[str], near: Mesh | None, bounds: float) -> Mesh:
    kind = d.choice(["icosphere"] * 3 + ["uv_sphere", "capsule", "box", "box", "cylinder", "panel", "quad", "soup"])
    if kind == "icosphere":
        sub = d.choice([0, 1, 2, 2, 3, 3] + ([5] if d.coin(0.05) else []))
        r = d.uniform(0.1, 0.8)
        lines.append(f"{var} = trimesh.creation.icosphere(subdivisions={sub}, radius={r})")
        half, tri = r, True
    elif kind == "uv_sphere":
        r = d.uniform(0.1, 0.8)
        lines.append(f"{var} = trimesh.creation.uv_sphere(radius={r}, count=[{d.int(3, 32)}, {d.int(3, 32)}])")
        half, tri = r, True
    elif kind == "capsule":
        r, h = d.uniform(0.05, 0.5), d.uniform(0.0, 1.5)
        lines.append(
            f"{var} = trimesh.creation.capsule(height={h}, radius={r}, count=[{d.int(4, 16)}, {d.int(4, 16)}])"
        )
        half, tri = r + h / 2, True
    elif kind == "cylinder":
        r, h = d.uniform(0.05, 0.6), d.uniform(0.01, 1.5)
        lines.append(f"{var} = trimesh.creation.cylinder(radius={r}, height={h}, sections={d.int(3, 32)})")
        half, tri = max(r, h / 2), True
    elif kind == "box":
        e = (d.uniform(0.05, 1.5), d.uniform(0.05, 1.5), d.uniform(0.05, 1.5))
        lines.append(f"{var} = trimesh.creation.box(extents={lit(e)})")
        half, tri = max(e) / 2, True
    elif kind == "panel":  # a thin box, of zero thickness at times
        w, h, t = d.uniform(0.2, 2.0), d.uniform(0.2, 2.0), d.choice([0.01, 0.01, 1e-4, 1e-7, 0.0])
        ext = d.choice([(w, t, h), (w, h, t)])
        lines.append(f"{var} = trimesh.creation.box(extents={lit(ext)})")
        half, tri = max(w, h) / 2, True
    elif kind == "quad":  # two triangles, horizontal or upright, either winding
        w, h = d.uniform(0.1, 1.5), d.uniform(0.1, 1.5)
        quad = (
            [[-w, 0, -h], [w, 0, -h], [w, 0, h], [-w, 0, h]]
            if d.coin(0.5)
            else [[-w, -h, 0], [w, -h, 0], [w, h, 0], [-w, h, 0]]
        )
        faces = d.choice([[[0, 2, 1], [0, 3, 2]], [[0, 1, 2], [0, 2, 3]]])
        lines.append(f"{var} = (np.array({lit([[float(x) for x in v] for v in quad])}), np.array({faces}))")
        half, tri = max(w, h), False
    else:  # a soup of random triangles, its own seed in the snippet
        n, k = d.int(1, 200), d.int(0, 10**6)
        spread = d.choice([0.3, 1.0, 2.0])
        lines.append(
            f"{var} = (np.random.default_rng({k}).uniform(-{spread}, {spread}, ({3 * n}, 3)), "
            f"np.arange({3 * n}).reshape({n}, 3))"
        )
        half, tri = spread, False
    if tri and d.coin(0.3):
        angle, axis = d.uniform(0, 6.283), tuple(g(x) for x in d.unit())
        lines.append(f"{var}.apply_transform(trimesh.transformations.rotation_matrix({angle}, {lit(axis)}))")
    # Where: on the floor, floating, sunk into it, or touching / inside another object.
    how = d.choice(["on", "on", "float", "sunk", "touch", "intersect"] if near else ["on", "on", "float", "sunk"])
    if how in ("touch", "intersect") and near is not None:
        direction = d.unit() * np.array([1.0, 0.3, 1.0])
        direction /= np.linalg.norm(direction)
        gap = (near.half + half) * (1.0 if how == "touch" else d.uniform(0.1, 0.9))
        pos = tuple(g(x) for x in np.array(near.pos) + gap * direction)
    else:
        y = {"on": half, "float": half + d.uniform(0.2, 1.5), "sunk": half * d.uniform(-0.5, 0.9)}[how]
        pos = (d.uniform(-bounds, bounds), g(y), d.uniform(-bounds, bounds))
    if tri:
        lines.append(f"{var}.apply_translation({lit(pos)})")
    else:
        lines.append(f"{var} = ({var}[0] + np.array({lit(pos)}), {var}[1])")
    return Mesh(var, "object", tri, pos, half)


def modify(d: Draw, m: Mesh, lines: list[str]) -> None:
    """Flipped, opened, degenerate, duplicated: still valid meshes."""
    v, f = vf(m)
    if d.coin(0.15):
        lines.append(f"{m.var}.invert()" if m.trimesh else f"{m.var} = ({v}, {f}[:, ::-1])")
    if d.coin(0.1):
        p = d.choice([0.05, 0.3, 0.7, 0.95])
        lines.append(f"{m.var} = ({v}, {f}[np.random.default_rng({d.int(0, 999)}).random(len({f})) > {p}])")
        m.trimesh = False
    v, f = vf(m)
    if d.coin(0.08):  # repeated indices, collinear points, a sliver
        x, y, z = m.pos
        e = d.choice([1e-3, 1e-9, 0.3])
        pts = [[x, y, z], [x + e, y, z], [x + 2 * e, y, z], [x, y, z + 1e-12]]
        lines.append(f"_v, _f = np.asarray({v}, float), np.asarray({f})")
        lines.append(
            f"{m.var} = (np.vstack([_v, {lit(pts)}]), np.vstack([_f, [[0, 0, 1], [2, 2, 2]], "
            f"len(_v) + np.array([[0, 1, 2], [0, 1, 3]])]))"
        )
        m.trimesh = False
    v, f = vf(m)
    if d.coin(0.03):
        lines.append(f"{m.var} = ({v}, np.vstack([{f}, {f}]))")
        m.trimesh = False
    v, f = vf(m)
    if d.coin(0.03):  # a far vertex no face uses
        lines.append(f"{m.var} = (np.vstack([{v}, [[{d.choice([50.0, 1e4, -1e6])}, 0.0, 0.0]]]), {f})")
        m.trimesh = False


def transform(m: Mesh, s: float, t: tuple[float, float, float], lines: list[str]) -> None:
    if s == 1.0 and not any(t):
        return
    if m.trimesh:
        if s != 1.0:
            lines.append(f"{m.var}.apply_scale({s!r})")
        if any(t):
            lines.append(f"{m.var}.apply_translation({lit(t)})")
    else:
        scaled = f"np.asarray({m.var}[0], float)" + (f" * {s!r}" if s != 1.0 else "")
        lines.append(f"{m.var} = ({scaled} + np.array({lit(t)}), {m.var}[1])")


def retype(d: Draw, m: Mesh, lines: list[str]) -> None:
    """Other array types (valid), or a hostile mesh."""
    v, f = vf(m)
    if d.hostile("meshes"):
        # A bad vertex or face appended (the mesh may have lost every face).
        add = "np.vstack([np.asarray({v}, float), [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [{x}, 1.0, 0.0]]])"
        face = "np.vstack([np.asarray({f}, np.int64).reshape(-1, 3), len({v}) + np.array([[0, 1, {k}]])])"
        bad = d.choice(
            [
                f"{m.var} = ({add.format(v=v, x='np.nan')}, {face.format(f=f, v=v, k=2)})",
                f"{m.var} = ({add.format(v=v, x='np.inf')}, {face.format(f=f, v=v, k=2)})",
                f"{m.var} = ({add.format(v=v, x='1e39')}, {face.format(f=f, v=v, k=2)})",  # finite f64, inf in f32
                f"{m.var} = ({add.format(v=v, x='0.0')}, {face.format(f=f, v=v, k=3)})",  # out of range
                f"{m.var} = ({v}, np.vstack([np.asarray({f}, np.int64).reshape(-1, 3), [[0, 1, -1]]]))",
                f"{m.var} = ({v}, np.hstack([{f}, np.asarray({f})[:, :1]]))",
                f"{m.var} = (np.asarray({v})[:, :2], {f})",
                f"{m.var} = ({v}, np.asarray({f}) + 0.5)",
                f"{m.var} = ({v}, np.zeros((0, 3), np.int64))",
                f"{m.var} = (np.zeros((0, 3)), np.zeros((0, 3), np.int64))",
                f"{m.var} = ({v}, np.asarray({f}).astype(str))",
                f"{m.var} = (np.asarray({v}).astype(np.complex128), {f})",
                f"{m.var} = ({v},)",
            ]
        )
        lines.append(bad)
        m.trimesh = False
    elif d.coin(0.1):
        lines.append(
            d.choice(
                [
                    f"{m.var} = (np.asarray({v}, np.float32), np.asarray({f}, np.int64))",
                    f"{m.var} = (np.asarray({v}).tolist(), np.asarray({f}).tolist())",
                    f"{m.var} = (np.asfortranarray({v}), np.asarray({f}, np.uint32))",
                    f"{m.var} = (np.repeat(np.asarray({v}), 2, axis=0)[::2], np.asarray({f}, np.int32))",
                    f"{m.var} = (np.asarray({v}, np.float16), {f})",
                ]
            )
        )
        m.trimesh = False


def draw_meshes(d: Draw, lines: list[str]) -> tuple[list[Mesh], str, dict]:
    layout = d.choice(["floor", "floor", "floor", "walls", "room", "room", "single", "panels", "soup"])
    meshes: list[Mesh] = []
    room: dict = {}
    if layout in ("floor", "walls", "panels"):
        a, t = d.uniform(3.0, 12.0), d.choice([0.01, 0.01, 0.1, 0.5, 1e-4, 0.0])
        if d.coin(0.3):
            lines.append(
                f"m0 = (np.array([[-{a}, 0.0, -{a}], [{a}, 0.0, -{a}], [{a}, 0.0, {a}], [-{a}, 0.0, {a}]]), "
                f"np.array([[0, 2, 1], [0, 3, 2]]))"
            )
            meshes.append(Mesh("m0", "floor", False, (0.0, 0.0, 0.0), a))
        else:
            lines.append(f"m0 = trimesh.creation.box(extents=({2 * a}, {t}, {2 * a}))")
            lines.append(f"m0.apply_translation((0.0, {-t / 2}, 0.0))")
            meshes.append(Mesh("m0", "floor", True, (0.0, 0.0, 0.0), a))
        if layout == "walls":
            h = d.uniform(1.0, 4.0)
            for side in d.rng.permutation(4)[: d.int(1, 3)]:
                var = f"m{len(meshes)}"
                ext = (2 * a, h, 0.1) if side < 2 else (0.1, h, 2 * a)
                at = [(0.0, h / 2, a), (0.0, h / 2, -a), (a, h / 2, 0.0), (-a, h / 2, 0.0)][side]
                lines.append(f"{var} = trimesh.creation.box(extents={lit(ext)})")
                lines.append(f"{var}.apply_translation({lit(tuple(g(x) for x in at))})")
                meshes.append(Mesh(var, "wall", True, at, a))
    elif layout == "room":  # a closed box, inverted (faces inward) or not, with the camera inside
        r, h = d.uniform(3.0, 10.0), d.uniform(2.0, 5.0)
        lines.append(f"m0 = trimesh.creation.box(extents=({r}, {h}, {r}))")
        lines.append(f"m0.apply_translation((0.0, {h / 2}, 0.0))")
        if d.coin(0.6):
            lines.append("m0.invert()")
        meshes.append(Mesh("m0", "room", True, (0.0, h / 2, 0.0), r / 2))
        room = {"r": r, "h": h}
    count = {"floor": d.int(1, 4), "walls": d.int(1, 3), "room": d.int(0, 3), "single": 1, "panels": d.int(2, 5)}
    bounds = room["r"] / 3 if room else 2.0
    for _ in range(count.get(layout, 0)):
        near = meshes[-1] if meshes and meshes[-1].role == "object" else None
        meshes.append(draw_object(d, f"m{len(meshes)}", lines, near, bounds))
    if layout == "soup":
        for _ in range(d.int(1, 3)):
            var, n, k = f"m{len(meshes)}", d.int(1, 300), d.int(0, 10**6)
            lines.append(
                f"{var} = (np.random.default_rng({k}).uniform(-2.0, 2.0, ({3 * n}, 3)), "
                f"np.arange({3 * n}).reshape({n}, 3))"
            )
            meshes.append(Mesh(var, "object", False, (0.0, 0.0, 0.0), 2.0))
    for m in meshes:
        modify(d, m, lines)
    return meshes, layout, room


def draw_frame(d: Draw) -> tuple[float, tuple[float, float, float]]:
    s = 1.0 if d.coin(0.7) else float(d.choice([1e-6, 1e-4, 1e-2, 1e2, 1e4, 1e6, d.logu(1e-6, 1e6)]))
    if d.coin(0.75):
        return s, (0.0, 0.0, 0.0)
    far = float(d.choice([1e2, 1e4, 1e5, 1e6, 1e7]))
    return s, tuple(g(x * far) for x in d.unit())


def world(p: Any, s: float, t: tuple[float, float, float]) -> tuple[float, ...]:
    return tuple(float(s * float(x) + float(o)) for x, o in zip(p, t, strict=True))


def emission(d: Draw, name: str) -> dict:
    if d.hostile(name):
        return {name: Code(d.choice(["-1.0", "float('nan')", "float('inf')", "(1.0, 2.0)", "'white'", "1e39", "[]"]))}
    if d.coin(0.5):
        return {}
    return {name: d.choice([d.uniform(0.1, 10.0), (d.uniform(0, 5), d.uniform(0, 5), d.uniform(0, 5)), 0.0, 3.4e38])}


def draw_light(d: Draw, s: float, t: tuple, meshes: list[Mesh], room: dict) -> tuple[str, dict]:
    """The light's source and what the budget needs to know."""
    if d.coin(0.3):
        direction = d.unit() * 0.5 + np.array([0.0, -1.0, 0.0]) if d.coin(0.9) else d.unit()
        direction = tuple(g(x) for x in direction)
        up = tuple(g(x) for x in d.unit())
        if d.hostile("up"):
            up = d.choice([tuple(2 * x for x in direction), Code(d.choice(HOSTILE_VEC))])
        if d.hostile("direction"):
            direction = Code(d.choice(HOSTILE_VEC))
        r = d.rng.random()
        if r < 0.1:
            ang: Any = 0.0
        elif r < 0.3:
            ang = 0.53
        elif r < 0.6:
            ang = d.uniform(0.1, 20.0)
        elif r < 0.75:
            ang = d.uniform(20.0, 179.0)
        elif r < 0.8:
            ang = 179.0
        else:
            ang = (d.uniform(0.0, 60.0), d.uniform(0.1, 60.0))
        if d.hostile("angular_size"):
            ang = Code(
                d.choice(["179.5", "180.0", "-1.0", "float('nan')", "(0.0, 5.0)", "(5.0, 0.0)", "'1'", "(1, 2, 3)"])
            )
        return call("ss.DirectionalLight", direction, up, ang, **emission(d, "irradiance")), {"rect": False}
    # A rectangle: above the scene facing it, at times behind, inside or turned away.
    if room:
        c = np.array(
            [d.uniform(-0.3, 0.3) * room["r"], room["h"] * d.uniform(0.6, 0.97), d.uniform(-0.3, 0.3) * room["r"]]
        )
        if d.coin(0.1):
            c[1] = room["h"] + 1.0  # outside: the room's ceiling shadows all
    else:
        c = np.array([d.uniform(-2, 2), d.uniform(1.5, 6.0), d.uniform(-2, 2)])
    where = d.rng.random()
    if where < 0.04:
        c[1] = -d.uniform(0.5, 3.0)  # under the floor
    elif where < 0.08 and len(meshes) > 1:
        c = np.array(d.choice(meshes[1:]).pos)  # inside an object
    aim = np.array([d.uniform(-1, 1), 0.0, d.uniform(-1, 1)]) - c
    normal = aim / (np.linalg.norm(aim) or 1.0) + 0.2 * d.unit()
    if d.coin(0.05):
        normal = -normal  # turned away: everything behind its plane
    normal = tuple(g(x) for x in normal)
    up = tuple(g(x) for x in d.unit())
    if d.hostile("up"):
        up = d.choice([tuple(-3 * x for x in normal), Code(d.choice(HOSTILE_VEC))])
    if d.hostile("normal"):
        normal = Code(d.choice(HOSTILE_VEC))
    r = d.rng.random()
    if r < 0.4:
        size: Any = d.uniform(0.05, 3.0)
    elif r < 0.6:
        size = (d.uniform(0.01, 3.0), d.uniform(0.01, 3.0))
    elif r < 0.7:
        size = d.choice([0.0, (0.0, 0.0)])
    elif r < 0.8:
        size = d.logu(1e-7, 1e-2)
    elif r < 0.9:
        size = d.uniform(5.0, 50.0)
    elif r < 0.97:
        size = d.choice([1e3, 1e6, (1e4, 0.5)])
    else:
        size = d.choice([1e20, 1e30, 1e-30, None])
    if isinstance(size, tuple):
        size = tuple(g(x * s) for x in size)
    elif isinstance(size, float):
        size = g(size * s)
    if d.hostile("size"):
        size = Code(
            d.choice(["-1.0", "float('nan')", "float('inf')", "(1.0, 0.0)", "(1.0, 2.0, 3.0)", "'1'", "(-1.0, 1.0)"])
        )
    center = world(c, s, t)
    if d.hostile("center"):
        center = Code(d.choice(HOSTILE_VEC))
    shape = d.rng.random()
    if shape < 0.15 or shape < 0.25 and not room:
        # A disk or a sphere (issue 31) of the rectangle's size: its radius
        # a number (half the size's first side), at times hostile.
        radius: Any = size[0] if isinstance(size, tuple) else size
        radius = g(0.5 * radius) if isinstance(radius, float) else radius
        if d.hostile("radius"):
            radius = Code(d.choice(["0.0", "-1.0", "float('nan')", "float('inf')", "'1'", "(1.0, 2.0)"]))
        if shape < 0.15:
            light = call("ss.DiskLight", center, normal, radius, **emission(d, "radiance"))
            return light, {"rect": False, "big": False, "kind": "disk"}
        light = call("ss.SphereLight", center, radius, **emission(d, "radiance"))
        return light, {"rect": False, "big": False, "kind": "sphere"}
    light = call("ss.RectLight", center, normal, up, size, **emission(d, "radiance"))
    big = isinstance(size, (float, tuple)) and max(np.atleast_1d(np.asarray(size, float))) > 5 * s
    return light, {"rect": True, "big": big}


def draw_resolution(d: Draw, cap: float) -> Any:
    r = d.rng.random()
    if r < 0.05:
        w, h = d.int(1, 4), d.int(1, 8)
    elif r < 0.1:
        w, h = 640, 480
    else:
        w = d.int(16, 128) if r < 0.75 else d.int(128, 400)
        h = max(1, int(w * d.choice([0.75, 0.75, 0.5, 1.0, 1.5, d.uniform(0.1, 2.0)])))
    if w * h > cap:
        k = math.sqrt(cap / (w * h))
        w, h = max(1, int(w * k)), max(1, int(h * k))
    if d.hostile("resolution"):
        return Code(d.choice(HOSTILE_RES + ["(640, 480.5)", "(640, 0)", "(100000, 100000)"]))
    return (w, h) if d.coin(0.9) or w != h else w


def draw_camera(d: Draw, s: float, t: tuple, meshes: list[Mesh], room: dict, cap: float) -> str:
    target = np.array([d.uniform(-1, 1), d.uniform(0, 1), d.uniform(-1, 1)])
    if room:
        eye = np.array(
            [d.uniform(-0.4, 0.4) * room["r"], d.uniform(0.2, 0.8) * room["h"], d.uniform(-0.4, 0.4) * room["r"]]
        )
    elif len(meshes) == 1 and d.coin(0.3):
        eye = np.array(meshes[0].pos) + 0.1 * meshes[0].half * d.unit()  # inside the only object
    else:
        elev = np.radians(d.uniform(5, 85) if d.coin(0.92) else -d.uniform(5, 60))
        azim = np.radians(d.uniform(0, 360))
        dist = d.uniform(2.0, 10.0)
        eye = target + dist * np.array([np.cos(elev) * np.cos(azim), np.sin(elev), np.cos(elev) * np.sin(azim)])
    eye = np.array([g(x) for x in eye])
    up: Any = (0.0, 1.0, 0.0) if d.coin(0.9) else tuple(g(x) for x in d.unit())
    fov: Any = d.uniform(10.0, 100.0) if d.coin(0.9) else d.choice([1e-3, 1.0, 150.0, 170.0, 179.0, 179.9])
    kw: dict[str, Any] = {"eye": world(eye, s, t), "target": world(target, s, t), "up": up, "fov_y": fov}
    if d.hostile("camera"):  # degenerate
        which = d.choice(["same", "up", "upzero", "fov", "eye"])
        if which == "same":
            kw["target"] = kw["eye"]
        elif which == "up":
            kw["up"] = tuple(g(x) for x in (target - eye))
        elif which == "upzero":
            kw["up"] = (0.0, 0.0, 0.0)
        elif which == "fov":
            kw["fov_y"] = Code(d.choice(["0.0", "180.0", "-5.0", "float('nan')", "float('inf')", "'40'", "1e-300"]))
        else:
            kw["eye"] = Code(d.choice(HOSTILE_VEC))
    kw["resolution"] = draw_resolution(d, cap)
    return call("ss.Camera.look_at", **kw)


# --- methods ---------------------------------------------------------------

CAPS = ss.methods.capabilities()
NAMES = ["ssm", "bitmask", "exact", "pcss", "smoothies", "auto"]
#: The options a name takes beside it (the rest only in a config).
LOOSE = ("passes", "samples", "occluder_resolution", "hierarchy", "precision")
CONFIGS = {"ssm": "Ssm", "bitmask": "Bitmask", "exact": "Exact", "pcss": "PCSS", "smoothies": "Smoothies"}


def draw_resolution_option(d: Draw, budget: dict) -> Any:
    if d.coin(0.04):
        side = d.choice([2048, 4096, 8192])
        budget["big_maps"] = True
    else:
        side = d.int(8, 1024)
    return side if d.coin(0.6) else (side, d.int(8, 1024))


def option_value(d: Draw, method: str, opt: str, budget: dict) -> str:
    info = CAPS[method].options[opt]
    if d.hostile(opt):
        pool = {"int": HOSTILE_INT, "one_of": HOSTILE_INT + ["17"], "resolution": HOSTILE_RES, "float": HOSTILE_FLOAT}
        return d.choice(pool.get(info.kind, HOSTILE_CHOICE if info.kind == "choice" else HOSTILE_BOOL))
    if info.kind == "int":
        lo, hi = info.min or 1, info.max or 1 << 16
        if opt in ("samples", "probe"):
            v = d.choice([lo, d.int(1, 64), d.int(16, 1024), 256, d.int(1024, 4096)] + ([hi] if d.coin(0.1) else []))
            budget["samples"] = max(budget.get("samples", 0), v)
        else:
            v = d.choice([lo, hi, d.int(lo, hi)])
        return lit(int(v))
    if info.kind in ("one_of", "choice"):
        v = d.choice(list(info.choices))
        if opt == "samples":
            budget["samples"] = max(budget.get("samples", 0), v)
        return lit(v)
    if info.kind == "bool":
        return lit(d.choice([False, True]))
    if info.kind == "resolution":
        return lit(draw_resolution_option(d, budget))
    if info.kind == "float":
        if method == "auto":
            budget["target"] = True
            if opt == "error":
                return lit(d.choice([d.uniform(0.01, 0.3), 0.005, 0.5]))
            return lit(d.choice([d.uniform(0.01, 1.0), 1e-4]))
        return lit(d.choice([d.uniform(0.01, 2.0), 1e-6, 1e3]))
    raise AssertionError(f"option kind {info.kind}")


def draw_bias(d: Draw) -> str:
    kind = d.choice(["ConstantBias", "SlopeScaleBias", "LinearDepthBias", "BackFaces", "MidpointBias"])
    if kind in ("BackFaces", "MidpointBias"):
        return f"ss.{kind}()"
    kw = {}
    if kind == "ConstantBias" or d.coin(0.7):
        kw["constant"] = Code(d.choice(HOSTILE_FLOAT)) if d.hostile("constant") else d.uniform(0.0, 200.0)
    if kind != "ConstantBias" and d.coin(0.7):
        kw["slope"] = Code(d.choice(HOSTILE_FLOAT)) if d.hostile("slope") else d.uniform(0.0, 8.0)
    return call(f"ss.{kind}", **kw)


def draw_shadow_mapping(d: Draw, budget: dict) -> str:
    kw: dict[str, Any] = {}
    if d.coin(0.5):
        if d.hostile("resolution"):
            kw["resolution"] = Code(d.choice(HOSTILE_RES))
        else:
            side = d.choice([64, 256, 512, 1024, 2048, 2048, 4096] + ([8192] if d.coin(0.2) else []))
            kw["resolution"] = side if d.coin(0.7) else (side, d.choice([256, 1024, 2048]))
            budget["big_maps"] = budget.get("big_maps") or side >= 4096
    if d.coin(0.5):
        kw["bias"] = Code(d.choice(["'slope'", "3", "ss.PCF(size=3)"])) if d.hostile("bias") else Code(draw_bias(d))
    if d.coin(0.4):
        if d.hostile("size"):
            kw["filter"] = Code(f"ss.PCF(size={d.choice(HOSTILE_INT)})")
        else:
            kw["filter"] = Code(d.choice(["ss.PCF()", f"ss.PCF(size={d.int(1, 9)})"]))
    if d.coin(0.3):
        parts = {}
        if d.coin(0.5):
            parts["n"] = Code(d.choice(HOSTILE_FLOAT + ["0.0"])) if d.hostile("n") else d.logu(1e-3, 1e3)
        if d.coin(0.5):
            parts["vector"] = Code(d.choice(HOSTILE_CHOICE)) if d.hostile("vector") else d.choice(["middle", "camera"])
        kw["warp"] = Code(call("ss.LiSPSM", **parts))
    if d.coin(0.3):
        kw["focus"] = Code(d.choice(HOSTILE_BOOL)) if d.hostile("focus") else d.choice([False, True])
    if d.coin(0.3):
        parts = {}
        if d.coin(0.6):
            parts["iterations"] = Code(d.choice(HOSTILE_INT)) if d.hostile("iterations") else d.int(0, 8)
        if d.coin(0.6):
            parts["radius"] = Code(d.choice(HOSTILE_FLOAT)) if d.hostile("radius") else d.uniform(0.0, 8.0)
        kw["blur"] = Code(call("ss.EyeSpaceBlur", **parts))
    return call("ss.ShadowMapping", **kw)


def draw_method(d: Draw, budget: dict, eye: bool = True) -> tuple[str, dict[str, str]]:
    """(method source, loose options beside a name)."""
    if d.hostile("method"):
        bad = ["'bogus'", "''", "None", "3", "b'ssm'", "'SSM'", "ss.Ssm", "ss.PCF(size=3)", "['ssm']", "ss.BackFaces()"]
        return d.choice(bad), {}
    r = d.rng.random()
    if r < 0.35:  # a name, with its options beside it
        name = d.choice(NAMES + (["shadow_mapping"] if d.coin(0.1) else []))
        loose: dict[str, str] = {}
        if name in CONFIGS and d.coin(0.4):
            for opt in [o for o in LOOSE if o in CAPS[name].options]:
                if d.coin(0.4):
                    loose[opt] = option_value(d, name, opt, budget)
        if name == "exact" and "samples" not in loose:
            budget["samples"] = max(budget.get("samples", 0), 256)
        if d.hostile("options"):  # one that does not apply to this method
            opt = d.choice(["passes", "samples", "occluder_resolution", "hierarchy", "precision"])
            loose[opt] = d.choice(["2", "64", "128", "True", "'f64'"])
        return lit(name), loose
    if r < 0.85 or not eye:
        name = d.choice(list(CONFIGS) + ["auto"])
        if name == "auto":
            kw = {}
            if d.coin(0.5):
                target = d.choice(["error", "time"])
                kw[target] = Code(option_value(d, "auto", target, budget))
                if d.coin(0.1):
                    kw["time"] = Code(option_value(d, "auto", "time", budget))
            return call("ss.Auto", **kw), {}
        kw = {opt: Code(option_value(d, name, opt, budget)) for opt in CAPS[name].options if d.coin(0.5)}
        if name == "exact" and "samples" not in kw:
            budget["samples"] = max(budget.get("samples", 0), 256)
        return call(f"ss.{CONFIGS[name]}", **kw), {}
    return draw_shadow_mapping(d, budget), {}


def draw_keywords(d: Draw, budget: dict, n_meshes: int, eye: bool = True) -> dict[str, Any]:
    kw: dict[str, Any] = {}
    if eye and (d.coin(0.25) or d.hostile("map_resolution")):
        if d.hostile("map_resolution"):
            kw["map_resolution"] = Code(d.choice(HOSTILE_RES + ["float('nan')", "True"]))
        else:
            kw["map_resolution"] = draw_resolution_option(d, budget)
    for name in ("normal_offset", "depth_bias"):
        if d.coin(0.12) or d.hostile(name):
            kw[name] = Code(d.choice(HOSTILE_FLOAT + ["True"])) if d.hostile(name) else d.uniform(0.0, 4.0)
    r = d.rng.random()
    if d.hostile("backend"):
        kw["backend"] = Code(d.choice(["None", "3", "b'cpu'", "'GPU'", "''", "'cuda'", "['cpu']"]))
    elif r < 0.06:
        kw["backend"] = "gpu"
    elif r < 0.12:
        kw["backend"] = d.choice(["auto", "cpu"])
    if d.hostile("threads"):
        kw["threads"] = Code(d.choice(["0", "-1", "1025", "2.5", "'2'", "True", "2**64"]))
    elif d.coin(0.15):
        kw["threads"] = d.choice([1, 1, 2, 3, 16])
    if eye and (d.coin(0.3) or d.hostile("albedo")):
        if d.hostile("albedo"):
            kw["albedo"] = Code(
                d.choice(
                    ["-0.1", "1.5", "float('nan')", "'red'", "(0.5, 0.5)", f"[0.5] * {n_meshes + 1}", "[[0.5, 0.5]]"]
                )
            )
        else:
            kw["albedo"] = d.choice(
                [
                    d.uniform(0, 1),
                    (d.uniform(0, 1), d.uniform(0, 1), d.uniform(0, 1)),
                    [d.uniform(0, 1) for _ in range(n_meshes)],
                    [(d.uniform(0, 1), 0.5, 1.0)] * n_meshes,
                    0.0,
                    1.0,
                ]
            )
    if d.hostile("estimate_error"):
        kw["estimate_error"] = Code(d.choice(["'yes'", "1", "None", "0.5", "'Fixed'"]))
    elif d.coin(0.08):
        kw["estimate_error"] = d.choice([True, "timed", "fixed"])
    return kw


def pixel_cap(budget: dict, kw: dict) -> float:
    cap = 640 * 480.0
    if budget.get("samples"):
        cap = min(cap, 8e7 / budget["samples"])
    if budget.get("big_maps"):
        cap = min(cap, 160 * 120)
    if budget.get("target"):
        cap = min(cap, 160 * 120)
    if kw.get("backend") == "gpu":
        cap = min(cap, 64 * 48, 4e6 / max(budget.get("samples", 256), 1))
    return max(cap, 1.0)


def draw_case(seed: int, index: int) -> Case:
    d = Draw(seed, index)
    setup: list[str] = []
    meshes, layout, room = draw_meshes(d, setup)
    s, t = draw_frame(d)
    for m in meshes:
        transform(m, s, t, setup)
    for m in meshes:
        retype(d, m, setup)
    names = [m.var for m in meshes]
    steps: list[tuple[str, str]] = []
    split = d.coin(0.1) and meshes[0].role == "floor" and len(meshes) > 1
    if d.hostile("scene"):
        scene = d.choice(["ss.Scene(meshes=[])", "ss.Scene()", "ss.Scene(meshes='m0')", "ss.Scene(meshes=[m0, None])"])
    elif split:
        scene = f"ss.Scene(occluders=[{', '.join(names[1:])}], receivers=[{names[0]}])"
    elif len(names) == 1 and d.coin(0.5):
        scene = f"ss.Scene(meshes={names[0]})"
    else:
        scene = f"ss.Scene(meshes=[{', '.join(names)}])"
    steps.append(("scene", f"scene = {scene}"))
    light, light_info = draw_light(d, s, t, meshes, room)
    steps.append(("light", f"light = {light}"))
    budget: dict = {}
    method, loose = draw_method(d, budget)
    kw = draw_keywords(d, budget, len(meshes))
    cap = pixel_cap(budget, kw)
    steps.append(("camera", f"camera = {draw_camera(d, s, t, meshes, room, cap)}"))
    args = ["scene", "light", "camera"]
    if d.hostile("render"):  # a wrong object where the call takes a Scene, a light or a Camera
        k = d.int(0, 2)
        args[k] = d.choice([names[0], "None", "light" if k != 1 else "scene", "(light,)"])
    loose_src = "".join(f", {k}={v}" for k, v in loose.items())
    kw_src = "".join(f", {k}={lit(v)}" for k, v in kw.items())
    render_src = f"img = ss.render({', '.join(args)}, {method}{loose_src}{kw_src})"
    steps.append(("render", render_src))
    gpu = kw.get("backend") == "gpu"
    repeat = (
        not d.rate
        and d.coin(0.15)
        and kw.get("backend") in (None, "cpu")
        and "time=" not in method
        and "threads" not in kw
        and cap >= 1
    )
    if repeat:
        steps.append(("repeat", f"img2 = ss.render(scene, light, camera, {method}{loose_src}{kw_src}, threads=1)"))
    if d.coin(0.25):  # the light view of the same meshes
        mbudget: dict = {}
        mmethod, mloose = draw_method(d, mbudget, eye=False)
        mkw = draw_keywords(d, mbudget, len(meshes), eye=False)
        side = d.choice([16, 32, 64, 128, 256, d.int(1, 300)])
        if mbudget.get("samples"):
            side = max(1, min(side, int(math.sqrt(4e7 / mbudget["samples"]))))
        if mbudget.get("big_maps") or mbudget.get("target"):
            side = min(side, 64)
        if mkw.get("backend") == "gpu":
            side = min(side, 64)
            gpu = True
        res: Any = Code(d.choice(HOSTILE_RES)) if d.hostile("resolution") else side
        if d.hostile("extent"):
            mkw["extent"] = Code(d.choice(["0.0", "-1.0", "float('nan')", "1e7", "(1.0, 0.0)", "'1'"]))
        elif d.coin(0.2):
            mkw["extent"] = d.choice([d.uniform(0.05, 3.0), (d.uniform(0.05, 3.0), d.uniform(0.05, 3.0))])
        which = "scene"
        if meshes[0].role == "floor" and len(meshes) > 1 and d.coin(0.5):
            which = f"ss.Scene(occluders=[{', '.join(names[1:])}], receivers=[{names[0]}])"
        map_kw = {"resolution": res, "method": Code(mmethod), **{k: Code(v) for k, v in mloose.items()}, **mkw}
        steps.append(("map", f"sm = {call('ss.soft_shadow_map', Code(which), Code('light'), **map_kw)}"))
    label = (
        f"{layout} x{len(meshes)} s={s:g} |t|={max(map(abs, t)):g} "
        f"{light_info.get('kind', 'rect' if light_info['rect'] else 'sun')} {method}{loose_src}{kw_src}"
    )
    return Case(seed, index, setup, steps, label[:200], gpu, repeat, d.hostile_args)


# --------------------------------------------------------------------------
# Running a call and checking what it gives
# --------------------------------------------------------------------------


def peak_rss() -> int:
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def reset_peak() -> None:
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass


def refusal(e: BaseException, gpu: bool) -> tuple[str | None, str | None]:
    """(the argument it names, a failure or None)."""
    if isinstance(e, ss.GpuUnavailableError) and not gpu:
        return None, "GpuUnavailableError without backend='gpu'"
    if not isinstance(e, ALLOWED) and not isinstance(e, ss.GpuUnavailableError):
        return None, f"unexpected {type(e).__name__}"
    msg = str(e)
    prefix = msg.split(":", 1)[0].strip() if ":" in msg else ""
    m = NAMED.match(prefix)
    if not m:
        return None, "message names no argument"
    if m.group(1) not in KNOWN_NAMES:
        return prefix, f"message names {m.group(1)!r}, no argument of the call"
    return prefix, None


def check_image(img: Any, ns: dict) -> list[str]:
    bad: list[str] = []
    if not isinstance(img, ss.Image):
        return [f"returned {type(img).__name__}, not an Image"]
    w, h = ns["camera"].resolution
    n_meshes = len(ns["scene"].meshes)
    expect = {
        "visibility": ((h, w), np.float32),
        "shaded": ((h, w, 3), np.float32),
        "unshadowed": ((h, w, 3), np.float32),
        "depth": ((h, w), np.float32),
        "position": ((h, w, 3), np.float64),
        "normal": ((h, w, 3), np.float32),
        "mesh_id": ((h, w), np.int32),
    }
    for name, (shape, dtype) in expect.items():
        a = getattr(img, name)
        if not isinstance(a, np.ndarray) or a.shape != shape or a.dtype != dtype:
            bad.append(
                f"{name}: {getattr(a, 'shape', None)} {getattr(a, 'dtype', type(a).__name__)}, not {shape} {dtype}"
            )
    if bad:
        return bad
    vis, sh, un = img.visibility, img.shaded, img.unshadowed
    hit = img.mesh_id >= 0
    miss = ~hit
    with np.errstate(all="ignore"):
        if ((img.mesh_id < -1) | (img.mesh_id >= n_meshes)).any():
            bad.append(f"mesh_id: values outside [-1, {n_meshes})")
        if not np.isfinite(vis).all():
            bad.append(f"visibility: {int((~np.isfinite(vis)).sum())} non-finite pixels")
        if ((vis < 0) | (vis > 1)).any():
            bad.append(f"visibility: outside [0, 1] ({np.nanmin(vis)}, {np.nanmax(vis)})")
        if (vis[miss] != 1).any():
            bad.append(f"visibility: {int((vis[miss] != 1).sum())} pixels with no surface not 1")
        for name, a in (("shaded", sh), ("unshadowed", un)):
            if not np.isfinite(a).all():
                bad.append(f"{name}: {int((~np.isfinite(a)).any(axis=-1).sum())} non-finite pixels")
            if (a < 0).any():
                bad.append(f"{name}: negative values")
            if (a[miss] != 0).any():
                bad.append(f"{name}: non-zero where no surface")
        # exact, and ssm, bitmask and pcss under an area light, weigh their
        # samples (shaded = unshadowed * V_w): where V is 0 or 1 so is V_w,
        # and V_w lies in [0, 1] everywhere; the other methods shade with V.
        want = un * vis[..., None]
        kind = type(img.method).__name__
        area = not isinstance(img.light, ss.DirectionalLight)
        weighs = kind == "Exact" or (kind in ("Ssm", "Bitmask", "PCSS") and area)
        settled = (vis == 0) | (vis == 1) if weighs else np.ones_like(vis, bool)
        off = (np.abs(sh.astype(np.float64) - want) > 1e-5 * np.abs(want) + 1e-30) & settled[..., None]
        if off.any():
            bad.append(f"shaded: differs from unshadowed * visibility at {int(off.any(axis=-1).sum())} pixels")
        if (sh.astype(np.float64) > un * (1 + 1e-5) + 1e-30).any():
            bad.append("shaded: brighter than unshadowed")
        if not np.isinf(img.depth[miss]).all() or not (img.depth[miss] > 0).all():
            bad.append("depth: not +inf where no surface")
        if not np.isfinite(img.depth[hit]).all() or (img.depth[hit] < 0).any():
            bad.append(
                f"depth: {int((~np.isfinite(img.depth[hit]) | (img.depth[hit] < 0)).sum())} hit pixels not finite >= 0"
            )
        if not np.isnan(img.position[miss]).all():
            bad.append("position: not NaN where no surface")
        if not np.isfinite(img.position[hit]).all():
            bad.append(f"position: {int((~np.isfinite(img.position[hit])).any(axis=-1).sum())} hit pixels not finite")
        if (img.normal[miss] != 0).any():
            bad.append("normal: not 0 where no surface")
        norms = np.linalg.norm(img.normal[hit].astype(np.float64), axis=-1)
        if not (np.abs(norms - 1) < 1e-3).all():
            bad.append(f"normal: {int((~(np.abs(norms - 1) < 1e-3)).sum())} hit pixels without a unit normal")
        light = ns["light"]
        if isinstance(light, ss.RectLight) and hit.any() and not bad:
            c, n = np.array(light.center), np.asarray(light.n, float)
            p = img.position[hit]
            scale = max(float(np.abs(p).max()), float(np.abs(c).max()), max(light.size), 1e-300)
            behind = (p - c) @ n < -1e-4 * scale
            if (vis[hit][behind] != 0).any():
                bad.append(f"visibility: {int((vis[hit][behind] != 0).sum())} pixels behind the light's plane not 0")
    if isinstance(img.method, ss.Auto) or type(img.method).__name__ == "Auto":
        bad.append("method: the result's method is Auto, not the config that ran")
    est = img.error_estimate
    if est is not None:
        lo, hi = est.interval
        if not (0 <= lo <= hi <= 1) or not (np.isfinite(est.error) and 0 <= est.error <= 1):
            bad.append(f"error_estimate: error {est.error} interval {est.interval}")
    return bad


def check_map(sm: Any, ns: dict) -> list[str]:
    if not isinstance(sm, ss.ShadowMap):
        return [f"returned {type(sm).__name__}, not a ShadowMap"]
    v = sm.visibility
    bad = []
    if v.dtype != np.float32 or v.ndim != 2:
        return [f"visibility: {v.shape} {v.dtype}"]
    if sm.receiver_depth.shape != v.shape:
        bad.append(f"receiver_depth: shape {sm.receiver_depth.shape}, visibility {v.shape}")
    with np.errstate(all="ignore"):
        if not np.isfinite(v).all():
            bad.append(f"visibility: {int((~np.isfinite(v)).sum())} non-finite texels")
        if ((v < 0) | (v > 1)).any():
            bad.append(f"visibility: outside [0, 1] ({np.nanmin(v)}, {np.nanmax(v)})")
        if not bad and (v[~np.isfinite(sm.receiver_depth)] != 1).any():
            bad.append("visibility: texels with no receiver not 1")
    return bad


def run_case(case: Case, on_step=None) -> dict:
    """Runs the case's steps here: {"steps": [...], "failures": [...]}."""
    import trimesh

    ns: dict[str, Any] = {"np": np, "trimesh": trimesh, "ss": ss}
    steps: list[dict] = []
    failures: list[dict] = []

    def fail(step: str, what: str, detail: str = "") -> None:
        failures.append({"step": step, "what": what, "detail": detail[-3000:], "snippet": case.snippet(step)})

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            exec("\n".join(case.setup), ns)
    except Exception:  # noqa: BLE001 - the harness's own meshes: a bug here
        fail("setup", "the harness's mesh setup raised", traceback.format_exc())
        return {"steps": steps, "failures": failures}
    done: set[str] = set()
    needs = {"render": {"scene", "light", "camera"}, "repeat": {"render"}, "map": {"scene", "light"}}
    for name, src in case.steps:
        if not needs.get(name, set()) <= done:
            continue
        if on_step:
            on_step(name)
        rec: dict[str, Any] = {"step": name}
        reset_peak()
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                exec(src, ns)
        except KeyboardInterrupt:
            raise
        except BaseException as e:  # noqa: BLE001 - the point is to see everything (pyo3 panics included)
            rec["s"] = time.perf_counter() - t0
            rec["outcome"] = f"refused {type(e).__name__}"
            arg, problem = refusal(e, case.gpu)
            rec["arg"] = arg
            if problem:
                rec["outcome"] = f"failed {type(e).__name__}"
                fail(name, problem, f"{type(e).__name__}: {e}\n" + "".join(traceback.format_tb(e.__traceback__)[-3:]))
        else:
            rec["s"] = time.perf_counter() - t0
            rec["outcome"] = "ok"
            done.add(name)
            problems: list[str] = []
            try:
                if name in ("render", "repeat"):
                    problems = check_image(ns["img" if name == "render" else "img2"], ns)
                    if name == "repeat" and not problems:
                        a, b = ns["img"].visibility, ns["img2"].visibility
                        if not np.array_equal(a, b):
                            diff = np.abs(a.astype(np.float64) - b)
                            problems.append(
                                f"visibility: a second render of the Scene with threads=1 differs at "
                                f"{int((diff > 0).sum())} pixels (max {diff.max():.3g})"
                            )
                elif name == "map":
                    problems = check_map(ns["sm"], ns)
            except Exception:  # noqa: BLE001
                problems = ["the checks raised: " + traceback.format_exc(limit=2)]
            for p in problems:
                fail(name, p)
            if problems:
                rec["outcome"] = "wrong output"
            rec["warnings"] = sorted({f"{w.category.__name__}: {str(w.message)[:80]}" for w in caught})
        rec["peak"] = peak_rss()
        if rec["s"] > SLOW_S:
            fail(name, f"slow: over {SLOW_S:.0f} s", f"took {rec['s']:.1f} s")
        if rec["peak"] > MEMORY_FAIL:
            fail(name, f"memory: peak RSS over {MEMORY_FAIL / GIB:.0f} GiB", f"peak {rec['peak'] / GIB:.2f} GiB")
        steps.append(rec)
    return {"steps": steps, "failures": failures}


# --------------------------------------------------------------------------
# The worker, the watchdog and the summary
# --------------------------------------------------------------------------


def emit(msg: dict) -> None:
    sys.stdout.write(json.dumps(msg) + "\n")
    sys.stdout.flush()


def worker(seed: int, start: int, stop: int | None, until: float) -> None:
    i = start
    while (stop is None or i < stop) and time.time() < until:
        case = draw_case(seed, i)
        emit({"ev": "start", "i": i, "label": case.label, "snippet": case.snippet()})
        result = run_case(case, on_step=lambda step, i=i: emit({"ev": "step", "i": i, "step": step}))
        emit({"ev": "done", "i": i, **result})
        i += 1
    emit({"ev": "end", "i": i})


@dataclass
class Summary:
    seed: int
    calls: int = 0
    outcomes: collections.Counter = field(default_factory=collections.Counter)
    named: collections.Counter = field(default_factory=collections.Counter)
    warnings: collections.Counter = field(default_factory=collections.Counter)
    times: list = field(default_factory=list)  # (seconds, index, step, label)
    peak: tuple = (0, -1, "")
    failures: list = field(default_factory=list)
    workers: int = 0
    reruns: int = 0  # calls run again: the extension was rewritten under the worker

    def add(self, i: int, label: str, result: dict) -> None:
        self.calls += 1
        for rec in result["steps"]:
            self.outcomes[f"{rec['step']} {rec['outcome']}"] += 1
            if rec.get("arg"):
                self.named[re.split(r"[\[.]", rec["arg"])[0]] += 1
            for w in rec.get("warnings", ()):
                self.warnings[w] += 1
            self.times.append((rec["s"], i, rec["step"], label))
            if rec["peak"] > self.peak[0]:
                self.peak = (rec["peak"], i, rec["step"])
        self.times = sorted(self.times, reverse=True)[:8]
        for f in result["failures"]:
            self.failures.append({"i": i, **f})


def signature(f: dict) -> str:
    detail = f["detail"].splitlines()[0] if f["detail"] else ""
    if f["what"].startswith(("slow", "memory", "crash", "hang")):
        detail = ""
    return re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "#", f"{f['step']}: {f['what']}: {detail}")[:160]


class LineReader:
    def __init__(self, fd: int) -> None:
        self.fd, self.buf = fd, b""

    def readline(self, timeout: float) -> bytes | None:
        """A line (b"" at EOF), or None after `timeout` seconds without one."""
        deadline = time.monotonic() + timeout
        while b"\n" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.fd], [], [], left)[0]:
                return None
            chunk = os.read(self.fd, 1 << 16)
            if not chunk:
                line, self.buf = self.buf, b""
                return line
            self.buf += chunk
        line, _, self.buf = self.buf.partition(b"\n")
        return line + b"\n"


def _extension_stamp() -> tuple[int, int, int]:
    st = os.stat(ss._core.__file__)
    return st.st_ino, st.st_size, st.st_mtime_ns


def _tail(f: Any) -> str:
    f.seek(0)
    text = f.read().decode(errors="replace")
    # Mesa's lavapipe says this on every adapter probe; it is not the call's.
    return "\n".join(line for line in text.splitlines() if "XDG_RUNTIME_DIR" not in line)[-3000:]


def watch(seed: int, calls: int | None, seconds: float, hang: float, summary: Summary, log=print) -> None:
    """Runs calls [0, calls) in worker processes until `seconds` have passed,
    replacing a worker that crashed or hung (a failure of the call it was
    running) by one starting at the next call. A crash while the installed
    extension was rewritten (a rebuild under a running worker: SIGBUS) is
    not the call's: that call runs again in a fresh worker."""
    until = time.time() + seconds
    env = dict(os.environ)
    env.setdefault("SOFTSHADOW_MEMORY_LIMIT", str(MEMORY_LIMIT))
    start: int | None = 0
    last_report = time.time()
    while start is not None and (calls is None or start < calls) and time.time() < until:
        stamp = _extension_stamp()
        cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", "--seed", str(seed), "--start", str(start)]
        cmd += ["--until", repr(until)] + (["--stop", str(calls)] if calls is not None else [])
        with (
            tempfile.TemporaryFile() as stderr,
            subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=stderr, env=env) as proc,
        ):
            summary.workers += 1
            assert proc.stdout is not None
            reader = LineReader(proc.stdout.fileno())
            current: dict | None = None
            step, start = "import", None
            try:
                while True:
                    line = reader.readline(hang if current else max(hang, 120.0))
                    if line is None or line == b"":  # hung, or died without saying it ended
                        if line is None:
                            proc.kill()
                        proc.wait()
                        what = (
                            f"hang: no answer in {hang:.0f} s"
                            if line is None
                            else f"crash: exit status {proc.returncode}"
                        )
                        if current is None:
                            raise SystemExit(
                                f"fuzz_render: the worker failed before any call ({what}):\n{_tail(stderr)}"
                            )
                        if line == b"" and _extension_stamp() != stamp:
                            log(f"  call {current['i']}: worker {what} while softshadow._core was rewritten; again")
                            summary.reruns += 1
                            start = current["i"]
                            break
                        summary.calls += 1
                        summary.failures.append(
                            {
                                "i": current["i"],
                                "step": step,
                                "what": what,
                                "detail": _tail(stderr),
                                "snippet": current["snippet"],
                            }
                        )
                        start = current["i"] + 1
                        break
                    msg = json.loads(line)
                    if msg["ev"] == "start":
                        current, step = msg, "setup"
                    elif msg["ev"] == "step":
                        step = msg["step"]
                    elif msg["ev"] == "done":
                        summary.add(msg["i"], current["label"] if current else "", msg)
                        current = None
                        if time.time() - last_report > 60:
                            last_report = time.time()
                            log(f"  {summary.calls} calls, {len(summary.failures)} failures", flush=True)
                    elif msg["ev"] == "end":
                        break
            finally:
                if proc.poll() is None:
                    proc.kill()


def report(summary: Summary, elapsed: float, log=print) -> int:
    log(f"fuzz_render: {summary.calls} calls in {elapsed:.0f} s, seed {summary.seed}, {summary.workers} worker(s)")
    if summary.reruns:
        log(f"  ({summary.reruns} call(s) run again: softshadow._core was rewritten under a running worker)")
    log("outcomes:")
    for k, v in sorted(summary.outcomes.items()):
        log(f"  {k:36s} {v}")
    log("refusals by the argument named: " + ", ".join(f"{k} {v}" for k, v in summary.named.most_common()))
    if summary.warnings:
        log("warnings: " + "; ".join(f"{k} ({v})" for k, v in summary.warnings.most_common(8)))
    log("slowest steps:")
    for s, i, step, label in summary.times[:5]:
        log(f"  {s:7.2f} s  call {i} {step}: {label}")
    peak, i, step = summary.peak
    log(f"peak memory (VmHWM of a step): {peak / 2**20:.0f} MiB (call {i} {step})")
    groups: dict[str, list[dict]] = {}
    for f in summary.failures:
        groups.setdefault(signature(f), []).append(f)
    log(f"failures: {len(summary.failures)} ({len(groups)} distinct)")
    for sig, fs in groups.items():
        best = min(fs, key=lambda f: len(f["snippet"]))
        where = ", ".join(str(f["i"]) for f in fs[:20]) + (" ..." if len(fs) > 20 else "")
        log(f"\n=== {sig}  x{len(fs)}  (calls {where})")
        log(f"{best['what']}")
        if best["detail"]:
            log(best["detail"].rstrip())
        log(f"--- reproducer (call {best['i']}; --seed {summary.seed} --replay {best['i']}):")
        log(best["snippet"])
    return 1 if summary.failures else 0


def replay(seed: int, index: int) -> int:
    case = draw_case(seed, index)
    print(case.snippet())
    print("# hostile:", case.hostile or "none")
    result = run_case(case)
    for rec in result["steps"]:
        print(rec)
    for f in result["failures"]:
        print(f"FAILURE {f['step']}: {f['what']}\n{f['detail']}")
    return 1 if result["failures"] else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, help="fuzz for this long (no new call starts after it)")
    ap.add_argument("--seconds", type=float, help="the same, in seconds")
    ap.add_argument("--calls", type=int, help="at most this many calls")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--hang", type=float, default=180.0, help="seconds without an answer before a call is a hang")
    ap.add_argument("--replay", type=int, metavar="I", help="print call I of the seed and run it here")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--start", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--stop", type=int, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--until", type=float, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args.seed, args.start, args.stop, args.until or math.inf)
        return 0
    if args.replay is not None:
        return replay(args.seed, args.replay)
    seconds = 60 * args.minutes if args.minutes is not None else args.seconds
    if seconds is None and args.calls is None:
        args.calls = 200
    t0 = time.time()
    summary = Summary(args.seed)
    watch(args.seed, args.calls, math.inf if seconds is None else seconds, args.hang, summary)
    return report(summary, time.time() - t0)


if __name__ == "__main__":
    sys.exit(main())
