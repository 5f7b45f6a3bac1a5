"""Item k's parameters, drawn from the spec with a generator seeded by (seed, k).

``np.random.SeedSequence(seed, spawn_key=(k,))`` gives item k its own
stream, independent of every other item's and of which worker draws it, so
any subset of items regenerates bit for bit on any number of workers. The
stream is split in three (objects, light, camera) so that, say, a change of
the camera's ranges leaves the objects and the light of every item as they
were. The result is plain JSON values (the item's record) from which
:mod:`.build` makes the scene. With ``views = n``, the n items of one scene
(k // n alike) draw their objects and ground from the first one's objects
stream and their light and camera from their own.

Several lights (``lights_per_item``): their number comes from a stream of
its own (child 4 of item k's seed sequence; child 3 is the reference's
jitter, :func:`item_seed`), drawn only when the range is not one number;
the lights are then drawn one after the other from the light stream, each
table picked by weight then sampled as one light is. So the first light of
every item is the one a spec with one light per item draws.

Placement (per instance): the base mesh is scaled so that the largest side
of its bounding box is 1, stretched per axis, scaled by ``scale``, tilted by
``tilt`` degrees about a horizontal axis at a random angle, turned by
``yaw`` about +y, then moved so that its lowest point is at ``height`` (0 on
the ground) and its bounding box is centred on (x, z).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .spec import Color, LightSpec, ObjectSpec, Spec

Range = tuple[float, float]


def item_rngs(seed: int, k: int) -> tuple[np.random.Generator, np.random.Generator, np.random.Generator]:
    """The generators of item k: objects, light, camera."""
    root = np.random.SeedSequence(seed, spawn_key=(k,))
    a, b, c = (np.random.default_rng(s) for s in root.spawn(3))
    return a, b, c


def uniform(rng: np.random.Generator, r: Range) -> float:
    """Uniform in [low, high] (always one draw, so a fixed value keeps the stream aligned)."""
    u = float(rng.random())
    return r[0] if r[0] == r[1] else r[0] + (r[1] - r[0]) * u


def _color(rng: np.random.Generator, c: Color) -> list[float]:
    if c[0] == c[1] == c[2]:  # a grey range: one draw for the three channels
        g = uniform(rng, c[0])
        return [g, g, g]
    return [uniform(rng, r) for r in c]


def scene_item(spec: Spec, k: int) -> int:
    """The item whose objects stream item k's scene is drawn from: the first
    of its ``views`` (k itself when every item has its own scene)."""
    return k - k % spec.views


def sample_item(spec: Spec, k: int) -> dict[str, Any]:
    """Every random choice of item k, as JSON values. The objects and the
    ground come from the objects stream of :func:`scene_item` (shared by the
    ``views`` items of one scene), the light and camera from item k's own."""
    _, r_light, r_cam = item_rngs(spec.seed, k)
    r_obj = item_rngs(spec.seed, scene_item(spec, k))[0]
    objects: list[dict[str, Any]] = []
    for index, o in enumerate(spec.objects):
        objects += _instances(r_obj, index, o, spec)
    ground = None
    if spec.ground.enabled:
        ground = {"size": spec.ground.size, "albedo": _color(r_obj, spec.ground.albedo)}
    camera = _camera(r_cam, spec)
    if not spec.several_lights:
        return {"objects": objects, "ground": ground, "light": _pick_light(r_light, spec), "camera": camera}
    lights = [_pick_light(r_light, spec) for _ in range(light_count(spec, k))]
    return {"objects": objects, "ground": ground, "lights": lights, "camera": camera}


def light_count(spec: Spec, k: int) -> int:
    """How many lights item k draws (``lights_per_item``), from its own stream."""
    lo, hi = spec.lights_per_item
    if lo == hi:
        return lo
    rng = np.random.default_rng(np.random.SeedSequence(spec.seed, spawn_key=(k, 4)))
    return int(rng.integers(lo, hi + 1))


def _pick_light(rng: np.random.Generator, spec: Spec) -> dict[str, Any]:
    """One light: a ``[[lights]]`` table by weight (no draw when there is one), then its values."""
    weights = np.array([light.weight for light in spec.lights])
    which = int(rng.choice(len(spec.lights), p=weights / weights.sum())) if len(spec.lights) > 1 else 0
    return _light(rng, which, spec.lights[which])


def _instances(rng: np.random.Generator, index: int, o: ObjectSpec, spec: Spec) -> list[dict[str, Any]]:
    spots: list[tuple[float, float]] = []
    if o.layout == "random":
        n = int(rng.integers(o.count[0], o.count[1] + 1))
        for _ in range(n):
            spots.append((uniform(rng, o.x), uniform(rng, o.z)))
    else:
        nx, nz = o.grid
        for i in range(nx):
            for j in range(nz):
                keep = float(rng.random()) < o.fill
                dx, dz = (o.jitter * (2.0 * float(rng.random()) - 1.0) for _ in range(2))
                if keep:
                    spots.append(((i - 0.5 * (nx - 1)) * o.spacing[0] + dx, (j - 0.5 * (nz - 1)) * o.spacing[1] + dz))
    out = []
    for x, z in spots:
        inst: dict[str, Any] = {"entry": index, "kind": o.kind}
        if o.kind == "mesh":
            f = o.files[int(rng.integers(len(o.files)))] if len(o.files) > 1 else o.files[0]
            inst["file"] = spec.relative(f)
            if spec.file_colors(o, f):
                inst["colors"] = "file"  # the file's own colours, not the albedo (build.py)
        inst.update(
            scale=uniform(rng, o.scale),
            stretch=[uniform(rng, r) for r in o.stretch],
            tilt=uniform(rng, o.tilt),
            tilt_axis=360.0 * float(rng.random()),
            yaw=uniform(rng, o.yaw),
            x=x,
            z=z,
            height=uniform(rng, o.height) if o.placement == "floating" else 0.0,
            albedo=_color(rng, o.albedo),
        )
        out.append(inst)
    return out


def direction(azimuth: float, elevation: float) -> np.ndarray:
    """Unit vector at ``azimuth`` (from +x toward +z) and ``elevation`` (above the horizon), degrees."""
    a, e = np.radians(azimuth), np.radians(elevation)
    return np.array([np.cos(e) * np.cos(a), np.sin(e), np.cos(e) * np.sin(a)])


def tangent_up(azimuth: float, elevation: float) -> np.ndarray:
    """The unit vector of growing elevation: perpendicular to :func:`direction`, never parallel to it."""
    a, e = np.radians(azimuth), np.radians(elevation)
    return np.array([-np.sin(e) * np.cos(a), np.cos(e), -np.sin(e) * np.sin(a)])


def _light(rng: np.random.Generator, which: int, s: LightSpec) -> dict[str, Any]:
    az, el = uniform(rng, s.azimuth), uniform(rng, s.elevation)
    d, up = direction(az, el), tangent_up(az, el)
    if s.kind in ("disk", "sphere"):
        radius = uniform(rng, s.radius)
        dist = uniform(rng, s.distance)
        center = np.asarray(s.target) + dist * d
        out: dict[str, Any] = {
            "entry": which, "kind": s.kind, "azimuth": az, "elevation": el, "distance": dist,
            "center": center.tolist(),
        }  # fmt: skip
        if s.kind == "disk":
            out["normal"] = (-d).tolist()  # facing the target
        out.update(radius=radius, radiance=uniform(rng, s.power))
        return out
    if s.kind == "rect":
        width = uniform(rng, s.size)
        height = width * uniform(rng, s.aspect)
        dist = uniform(rng, s.distance)
        center = np.asarray(s.target) + dist * d
        return {
            "entry": which, "kind": "rect", "azimuth": az, "elevation": el, "distance": dist,
            "center": center.tolist(), "normal": (-d).tolist(), "up": up.tolist(),
            "size": [width, height], "radiance": uniform(rng, s.power),
        }  # fmt: skip
    angle = uniform(rng, s.angular_size)
    return {
        "entry": which, "kind": "sun", "azimuth": az, "elevation": el,
        "direction": (-d).tolist(), "up": up.tolist(),
        "angular_size": [angle, angle], "irradiance": uniform(rng, s.power),
    }  # fmt: skip


def _camera(rng: np.random.Generator, spec: Spec) -> dict[str, Any]:
    c = spec.camera
    az, el, dist = uniform(rng, c.azimuth), uniform(rng, c.elevation), uniform(rng, c.distance)
    target = np.array([uniform(rng, c.target_x), uniform(rng, c.look_at_height), uniform(rng, c.target_z)])
    eye = target + dist * direction(az, el)
    return {
        "azimuth": az, "elevation": el, "distance": dist, "eye": eye.tolist(), "target": target.tolist(),
        "up": [0.0, 1.0, 0.0], "fov_y": uniform(rng, c.fov_y), "resolution": list(c.resolution),
    }  # fmt: skip


def item_seed(seed: int, k: int, light: int = 0) -> int:
    """A 32-bit seed of item k for what draws its own numbers (the Mitsuba
    reference's jitter), for its light ``light``: child 3 of its seed
    sequence for the first, 4 + light for the others (4 draws the number of
    lights, :func:`light_count`)."""
    child = 3 if light == 0 else 4 + light
    return int(np.random.SeedSequence(seed, spawn_key=(k, child)).generate_state(1)[0])
