"""Eye-view reference visibility: what fraction of the light each pixel's surface sees.

:func:`render_visibility` traces, with Mitsuba 3, one camera ray through the
centre of every pixel and then shadow rays from the first surface it hits,
and returns a :class:`ReferenceImage`: the visibility and the geometry of the
first hits (mask, depth, position, normal, mesh index).

Scene
-----
``scene.meshes`` is a list of ``(vertices (n, 3), faces (m, 3))`` pairs (or
objects with ``.vertices`` and ``.faces``). Every mesh is seen by the camera
and blocks light, itself included (self-shadowing); meshes are two-sided.
``mesh_id`` indexes this list (empty meshes are kept in the numbering but can
never be hit).

Camera rays
-----------
Pixel ``[j, i]`` (row j from the top) is the ray Mitsuba's perspective sensor
for the camera (:func:`camera_sensor`) samples at film position
``((i + 1/2)/W, (j + 1/2)/H)``, which is the camera's
``ray_directions()[j, i]`` from ``camera.eye`` (checked in
tests/eye_view/test_camera.py). The sensor starts its rays on the near plane
(``near_clip``, 0.01), so surfaces nearer than that are not seen, and
positions are taken from the intersection's ``p``, never from ``eye + t d``.
``depth`` is the distance of ``p`` along the optical axis,
``(p - eye) . forward``; ``normal`` the geometric (face) normal, flipped to
face the camera.

Rectangular light (``center`` c, ``normal``, ``up``, ``size``)
---------------------------------------------------------------
Frame ``n = normalize(normal)`` (into the scene), ``v = normalize(up - (up.n) n)``,
``u = n x v``; ``size = (sx, sy)`` is the full extent along u and v. The
visibility of a point p is the fraction of the rectangle's *area* (uniform,
no cosine) whose segment to p is clear of every mesh, estimated with K
stratified jittered samples ``c + s u + t v`` (the grid and jitter of
``_rays``). The light emits toward +n only: a point with ``(p - c).n <= 0``
gets 0 and no ray.

Directional light (``direction``, ``up``, ``angular_size``)
-----------------------------------------------------------
``n = normalize(direction)`` is the direction the light *travels*; v and u as
above. The light is the set of travel directions ``n + x u + y v`` with
``|x| <= tan(a_u / 2)``, ``|y| <= tan(a_v / 2)``, uniform in (x, y), where
``angular_size = (a_u, a_v)`` are full angles in degrees. The visibility of p
is the fraction of that rectangle of (x, y) whose ray from p along
``-normalize(n + x u + y v)`` (unbounded) hits nothing, estimated with the
same stratified jitter over the (x, y) rectangle. ``angular_size = (0, 0)``
is a hard sun: one ray along ``-n`` per point, and ``samples`` is 1.

Disk light (``center`` c, ``normal``, ``radius`` R)
---------------------------------------------------
A one-sided disk emitting toward ``n = normalize(normal)``. The visibility
of p is the fraction of the disk's *area* (uniform, no cosine) whose segment
to p is clear, estimated with K samples ``c + s u + t v``: the rectangle's
stratified jitter drawn over the square [-1, 1]^2 (the same grid, the same
draw order) and carried onto the unit disk by Shirley and Chiu's concentric
map, which preserves area (so the strata stay equal-area), then scaled by R.
(u, v) is any orthonormal pair across n (the disk is symmetric about its
axis); here ``v`` is the world axis least aligned with n, made orthogonal to
it, and ``u = n x v``. A point with ``(p - c).n <= 0`` gets 0 and no ray.

Sphere light (``center`` c, ``radius`` R)
-----------------------------------------
A sphere emitting over its whole surface. From a point p at distance
``d = |c - p| > R`` it covers the cone of half-angle ``alpha = asin(R/d)``
about ``c - p``; the visibility of p is the fraction of that cone's *solid
angle* whose rays are clear (the sphere is not an occluder). K directions are
sampled uniformly in solid angle, ``cos theta = 1 - u1 (1 - cos alpha)``,
``phi = 2 pi u2`` about the axis, with (u1, u2) the rectangle's stratified
jitter over the unit square; each ray goes to the point where that direction
first meets the sphere (its near surface), and stops ``ShadowEpsilon`` short
of it, as a rectangle's ray does before its sample. These targets are
computed per point in float64 NumPy and rounded to float32. A point at or
inside the sphere (``d <= R``) gets 0 and no ray.

Parts of a disk or a sphere below a point's horizon (behind its surface) are
sampled like the rest: the ray leaves through the surface's far side, and
only other geometry can block it. The visibility is geometric; the cosine
(and the horizon) belong to the shading.

Shadow rays
-----------
Rays start where Mitsuba's ``SurfaceInteraction.spawn_ray_to`` (rectangular
and disk lights: toward the sample point; sphere: toward the sample's point
on the sphere; stopping ``ShadowEpsilon`` short of it) and ``spawn_ray``
(directional light) start them: the origin is moved off the surface along
the geometric normal by ``(1 + max|p|) * RayEpsilon``, to the side the ray
leaves by, so a surface never shadows itself by round-off. The first hits'
``p`` and ``n`` are kept as float32 NumPy arrays; each batch of shadow rays
rebuilds a ``SurfaceInteraction3f`` holding only ``p``, ``n`` and ``time``
(the fields the spawn functions read; a default-constructed one has empty
fields, and an empty ``time`` crashes ``ray_test``), each pixel's values
repeated for its K samples by a Dr.Jit gather, and calls the spawn function
on it, so the offset is Mitsuba's own code. The jitter (float64, NumPy)
gives each sample's offsets (s, t) along u and v; the sample point
``c + s u + t v`` or travel direction ``n + s u + t v`` is formed in float32
by Dr.Jit, inside the tracing kernel (a sphere's targets, per point, come from
NumPy). Rays are traced by ``Scene.ray_test`` in batches of at most
``_rays.MAX_RAYS_PER_BATCH``; the jitter is drawn pixel-major from one NumPy
generator seeded by ``seed``, so the image is deterministic and does not
depend on batching.

In the ``scalar_rgb`` variant (no usable libLLVM) the same is done one ray
per Python call: fine for small images, slow for large ones.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np

from . import _rays
from ._inputs import _light_frame, _mesh_arrays, _positive_int, _seed, _vector3
from ._mitsuba import _mitsuba, _mitsuba_mesh
from ._rays import _grid_shape, _points_per_batch, _stratified_offsets
from .camera import camera_sensor

__all__ = ["ReferenceImage", "render_visibility"]


@dataclass(frozen=True, eq=False)
class ReferenceImage:
    """An eye-view reference: visibility and first-hit geometry per pixel.

    Attributes
    ----------
    visibility : numpy.ndarray, (H, W) float32
        Fraction of the light seen from the pixel's surface, a multiple of
        1/samples; 1.0 where the pixel sees no surface.
    mask : numpy.ndarray, (H, W) bool
        Where the camera ray hits a mesh.
    depth : numpy.ndarray, (H, W) float32
        Distance of the hit along the camera's optical axis (``forward``);
        inf where no hit.
    position : numpy.ndarray, (H, W, 3) float64
        World position of the hit (Mitsuba's float32 ``si.p``); NaN where no hit.
    normal : numpy.ndarray, (H, W, 3) float32
        Unit geometric normal of the hit triangle, facing the camera; zeros
        where no hit.
    mesh_id : numpy.ndarray, (H, W) int32
        Index into ``scene.meshes`` of the hit mesh; -1 where no hit.
    samples : int
        Light samples per pixel (1 for a hard sun).
    time_first_hits, time_shadow : float
        Wall time in seconds of the camera rays (sensor, ``ray_intersect``,
        read-back) and of the shadow rays (sampling, ``ray_test``).
    rays : int
        Number of shadow rays traced.
    """

    visibility: np.ndarray
    mask: np.ndarray
    depth: np.ndarray
    position: np.ndarray
    normal: np.ndarray
    mesh_id: np.ndarray
    samples: int
    time_first_hits: float
    time_shadow: float
    rays: int

    def __repr__(self) -> str:
        height, width = self.visibility.shape
        return (
            f"ReferenceImage({width}x{height}, hits={int(self.mask.sum())}, samples={self.samples}, "
            f"rays={self.rays}, first_hits={self.time_first_hits:.3f}s, shadow={self.time_shadow:.3f}s)"
        )


# --------------------------------------------------------------------------
# Lights
# --------------------------------------------------------------------------


class _RectSampler:
    """Stratified jittered points ``origin + s u + t v`` on a rectangular light."""

    directional = False

    def __init__(self, light: Any, samples: int) -> None:
        self.c, self.u, self.v, self.n, self.sx, self.sy = _light_frame(light)
        self.origin = self.c
        self.grid = _grid_shape(samples, self.sx, self.sy)
        self.samples = samples

    def lit_side(self, points: np.ndarray) -> np.ndarray:
        """Points strictly in front of the light's plane (the side it emits to)."""
        result: np.ndarray = (points - self.c) @ self.n > 0.0
        return result

    def offsets(self, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Offsets (s, t) of the samples along u and v, each (count * K,) float32, pixel-major."""
        s, t = _stratified_offsets(count, self.grid, self.sx, self.sy, rng)
        return s.astype(np.float32).ravel(), t.astype(np.float32).ravel()


class _SunSampler:
    """Stratified jittered travel directions ``origin + x u + y v`` of a
    directional light (``origin`` = n); shadow rays go the opposite way."""

    directional = True

    def __init__(self, light: Any, samples: int) -> None:
        for attribute in ("direction", "up", "angular_size"):
            if not hasattr(light, attribute):
                raise TypeError(f"light has no attribute {attribute!r}")
        direction = _vector3(light.direction, "light.direction")
        up = _vector3(light.up, "light.up")
        try:
            angles = np.asarray(light.angular_size, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise TypeError("light.angular_size must be a sequence of 2 numbers") from exc
        if angles.shape != (2,) or not np.all(np.isfinite(angles)) or np.any(angles < 0) or np.any(angles >= 180):
            raise ValueError(f"light.angular_size must be 2 angles in [0, 180) degrees, got {angles}")
        length = np.linalg.norm(direction)
        if length == 0.0:
            raise ValueError("light.direction must be non-zero")
        self.n = direction / length
        v = up - np.dot(up, self.n) * self.n
        v_length = np.linalg.norm(v)
        if v_length <= 1e-9 * max(float(np.linalg.norm(up)), 1.0):
            raise ValueError("light.up must not be parallel to light.direction")
        self.v = v / v_length
        self.u = np.cross(self.n, self.v)
        self.origin = self.n
        # Full widths of the (x, y) rectangle of tangents.
        self.wx, self.wy = (2.0 * math.tan(math.radians(a) / 2.0) for a in angles)
        self.hard = self.wx == 0.0 and self.wy == 0.0
        self.samples = 1 if self.hard else samples
        self.grid = (1, 1) if self.hard else _grid_shape(samples, self.wx, self.wy)

    def lit_side(self, points: np.ndarray) -> np.ndarray:
        """Every point may see a light at infinity."""
        return np.ones(len(points), dtype=bool)

    def offsets(self, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Tangent offsets (x, y) along u and v, each (count * K,) float32, pixel-major."""
        if self.hard:
            zero = np.zeros(count, dtype=np.float32)
            return zero, zero
        x, y = _stratified_offsets(count, self.grid, self.wx, self.wy, rng)
        return x.astype(np.float32).ravel(), y.astype(np.float32).ravel()


def _concentric_disk(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shirley and Chiu's concentric map of [-1, 1]^2 onto the unit disk (area-preserving).

    Each square ring ``max(|a|, |b|) = r`` goes to the circle of radius r,
    its perimeter spread evenly over the angle, so equal areas of the square
    map to equal areas of the disk (up to the factor pi / 4).
    """
    radius = np.where(np.abs(a) > np.abs(b), a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        angle = np.where(
            np.abs(a) > np.abs(b),
            (np.pi / 4.0) * (b / a),
            (np.pi / 2.0) - (np.pi / 4.0) * (a / b),
        )
    angle = np.where(radius == 0.0, 0.0, angle)  # the centre: a = b = 0
    return radius * np.cos(angle), radius * np.sin(angle)


def _axis_frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(u, v)`` across the unit vector ``n``: v is the world axis least
    aligned with n made orthogonal to it, and ``u = n x v``."""
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(n)))] = 1.0
    v = axis - np.dot(axis, n) * n
    v /= np.linalg.norm(v)
    return np.cross(n, v), v


def _radius(light: Any) -> float:
    try:
        radius = float(light.radius)
    except (TypeError, ValueError) as exc:
        raise TypeError("light.radius must be a number") from exc
    if not (math.isfinite(radius) and radius > 0.0):
        raise ValueError(f"light.radius must be positive and finite, got {radius}")
    return radius


class _DiskSampler:
    """Stratified jittered points ``origin + s u + t v`` on a disk light,
    uniform over its area (the square's strata through the concentric map)."""

    directional = False

    def __init__(self, light: Any, samples: int) -> None:
        for attribute in ("center", "normal", "radius"):
            if not hasattr(light, attribute):
                raise TypeError(f"light has no attribute {attribute!r}")
        self.c = _vector3(light.center, "light.center")
        normal = _vector3(light.normal, "light.normal")
        self.radius = _radius(light)
        length = np.linalg.norm(normal)
        if length == 0.0:
            raise ValueError("light.normal must be non-zero")
        self.n = normal / length
        self.u, self.v = _axis_frame(self.n)
        self.origin = self.c
        self.grid = _grid_shape(samples, 1.0, 1.0)
        self.samples = samples

    def lit_side(self, points: np.ndarray) -> np.ndarray:
        """Points strictly in front of the disk's plane (the side it emits to)."""
        result: np.ndarray = (points - self.c) @ self.n > 0.0
        return result

    def offsets(self, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Offsets (s, t) of the samples along u and v, each (count * K,) float32, pixel-major."""
        a, b = _stratified_offsets(count, self.grid, 2.0, 2.0, rng)
        s, t = _concentric_disk(a, b)
        return (self.radius * s).astype(np.float32).ravel(), (self.radius * t).astype(np.float32).ravel()


class _SphereSampler:
    """Stratified jittered directions uniform in solid angle over the cone a
    sphere light subtends from each point; the targets are the directions'
    first points on the sphere, a different set per point."""

    directional = False

    def __init__(self, light: Any, samples: int) -> None:
        for attribute in ("center", "radius"):
            if not hasattr(light, attribute):
                raise TypeError(f"light has no attribute {attribute!r}")
        self.c = _vector3(light.center, "light.center")
        self.radius = _radius(light)
        self.grid = _grid_shape(samples, 1.0, 1.0)
        self.samples = samples

    def lit_side(self, points: np.ndarray) -> np.ndarray:
        """Points strictly outside the sphere."""
        result: np.ndarray = np.linalg.norm(points - self.c, axis=1) > self.radius
        return result

    def targets(self, points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The samples' points on the sphere, (count * K, 3) float32, pixel-major.

        ``points`` (count, 3) float64 lie outside the sphere. Computed in
        float64: ``1 - cos(alpha)`` as ``sin^2 / (1 + cos)`` so that far, small
        spheres keep their precision.
        """
        count = len(points)
        u1, u2 = _stratified_offsets(count, self.grid, 1.0, 1.0, rng)  # (count, K) in [-1/2, 1/2]
        u1 += 0.5
        u2 += 0.5
        to_center = self.c - points
        distance = np.linalg.norm(to_center, axis=1)
        axis = to_center / distance[:, None]
        sin2_alpha = (self.radius / distance) ** 2
        one_minus_cos_alpha = sin2_alpha / (1.0 + np.sqrt(1.0 - sin2_alpha))
        one_minus_cos = u1 * one_minus_cos_alpha[:, None]  # 1 - cos(theta), (count, K)
        cos_theta = 1.0 - one_minus_cos
        sin2_theta = np.maximum(one_minus_cos * (2.0 - one_minus_cos), 0.0)
        sin_theta = np.sqrt(sin2_theta)
        phi = (2.0 * np.pi) * u2
        # Per point, an orthonormal pair across the axis (Duff et al. 2017).
        sign = np.where(axis[:, 2] >= 0.0, 1.0, -1.0)
        a = -1.0 / (sign + axis[:, 2])
        b = axis[:, 0] * axis[:, 1] * a
        e1 = np.stack([1.0 + sign * axis[:, 0] ** 2 * a, sign * b, -sign * axis[:, 0]], axis=1)
        e2 = np.stack([b, sign + axis[:, 1] ** 2 * a, -axis[:, 1]], axis=1)
        # Distance along each direction to the sphere's near surface.
        d = distance[:, None]
        reach = d * cos_theta - np.sqrt(np.maximum(self.radius**2 - d * d * sin2_theta, 0.0))
        x, y = sin_theta * np.cos(phi), sin_theta * np.sin(phi)
        targets = np.empty((count, self.samples, 3), dtype=np.float32)
        for k in range(3):
            direction = cos_theta * axis[:, k, None] + x * e1[:, k, None] + y * e2[:, k, None]
            targets[..., k] = points[:, k, None] + reach * direction
        return targets.reshape(-1, 3)


#: Any light's sampler: samples ``origin + s u + t v`` (see :func:`_shadow_vector`),
#: or, for a sphere, world targets per point (:meth:`_SphereSampler.targets`).
Sampler: TypeAlias = "_RectSampler | _SunSampler | _DiskSampler | _SphereSampler"


def _sampler(light: Any, samples: int) -> Sampler:
    """The sampler of ``light``: directional (``direction``), disk (``radius``
    and ``normal``), sphere (``radius``) or rectangular (the rest)."""
    if hasattr(light, "direction"):
        return _SunSampler(light, samples)
    if hasattr(light, "radius"):
        return _DiskSampler(light, samples) if hasattr(light, "normal") else _SphereSampler(light, samples)
    return _RectSampler(light, samples)


# --------------------------------------------------------------------------
# Inputs
# --------------------------------------------------------------------------


def _scene_meshes(scene: Any) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """``(index in scene.meshes, float32 vertices, uint32 faces)`` of the non-empty meshes."""
    if not hasattr(scene, "meshes"):
        raise TypeError("scene has no attribute 'meshes'")
    meshes = scene.meshes
    arrays = _mesh_arrays(meshes, "scene.meshes")  # validates; drops empty meshes
    indices = []
    for index, mesh in enumerate(meshes):
        faces = mesh.faces if hasattr(mesh, "vertices") and hasattr(mesh, "faces") else mesh[1]
        if np.asarray(faces).size:
            indices.append(index)
    assert len(indices) == len(arrays)
    return [(index, vertices, faces) for index, (vertices, faces) in zip(indices, arrays, strict=True)]


def _resolution(camera: Any) -> tuple[int, int]:
    """``(W, H)`` of the camera."""
    if not hasattr(camera, "resolution"):
        raise TypeError("camera has no attribute 'resolution'")
    width, height = camera.resolution
    return _positive_int(width, "camera.resolution[0]"), _positive_int(height, "camera.resolution[1]")


# --------------------------------------------------------------------------
# Rendering
# --------------------------------------------------------------------------


def render_visibility(
    scene: Any,
    light: Any,
    camera: Any,
    samples: int = 1024,
    *,
    seed: int = 0,
) -> ReferenceImage:
    """Reference visibility of the surface seen through every pixel.

    Parameters
    ----------
    scene : object
        Anything with ``meshes``: a list of ``(vertices (n, 3), faces (m, 3))``
        pairs (or objects with ``.vertices`` and ``.faces``). Every mesh is
        seen and casts shadows, on itself too.
    light : object
        A rectangular light (``center``, ``normal``, ``up``, ``size``), a
        directional one (``direction``, ``up``, ``angular_size`` in degrees),
        a disk (``center``, ``normal``, ``radius``) or a sphere (``center``,
        ``radius``), e.g. :class:`softshadow.DiskLight` and
        :class:`softshadow.SphereLight`; told apart by their attributes:
        ``direction`` a directional light, ``radius`` with ``normal`` a
        disk, ``radius`` alone a sphere, otherwise a rectangle. See the
        module docstring for their conventions.
    camera : softshadow.Camera
        The eye; its Mitsuba sensor (:func:`camera_sensor`) shoots one ray
        through each pixel centre.
    samples : int, optional
        Light samples per pixel K, stratified on the grid of
        :func:`softshadow.reference.visibility_at_points` (a disk's and a
        sphere's over the unit square, then mapped) and jittered
        independently per pixel. Ignored (1) for a hard sun.
    seed : int, optional
        Seed of the jitter; the image is deterministic for a given seed and
        independent of batching.

    Returns
    -------
    ReferenceImage
        Visibility, mask, depth, position, normal and mesh index per pixel,
        and timings.
    """
    meshes = _scene_meshes(scene)
    samples = _positive_int(samples, "samples")
    rng = np.random.default_rng(_seed(seed))
    sampler = _sampler(light, samples)
    width, height = _resolution(camera)
    eye = _vector3(camera.eye, "camera.eye")
    forward = _vector3(camera.forward, "camera.forward")

    mi, dr = _mitsuba()
    scalar = mi.variant().startswith("scalar")
    objects = []
    scene_dict: dict[str, Any] = {"type": "scene"}
    for index, vertices, faces in meshes:
        name = f"mesh_{index}"
        shape = _mitsuba_mesh(mi, name, vertices, faces)
        objects.append((index, shape))
        scene_dict[name] = shape
    mitsuba_scene = mi.load_dict(scene_dict)
    sensor = mi.load_dict(camera_sensor(camera))

    start = time.perf_counter()
    first_hits = _first_hits_scalar if scalar else _first_hits_vector
    hit, p32, n32, ids = first_hits(mi, dr, mitsuba_scene, sensor, objects, width, height)
    time_first_hits = time.perf_counter() - start

    start = time.perf_counter()
    position = p32.astype(np.float64)
    visible = np.zeros(len(p32), dtype=np.float32)
    lit = np.flatnonzero(sampler.lit_side(position))
    k = sampler.samples
    per_batch = _points_per_batch(k)
    trace = _shadow_scalar if scalar else _shadow_vector
    for first in range(0, len(lit), per_batch):
        chosen = lit[first : first + per_batch]
        if isinstance(sampler, _SphereSampler):
            targets = sampler.targets(position[chosen], rng)
            blocked = trace(mi, dr, mitsuba_scene, p32[chosen], n32[chosen], k, sampler, None, None, targets)
        else:
            s, t = sampler.offsets(len(chosen), rng)
            blocked = trace(mi, dr, mitsuba_scene, p32[chosen], n32[chosen], k, sampler, s, t)
        visible[chosen] = 1.0 - blocked.reshape(len(chosen), k).mean(axis=1)
    time_shadow = time.perf_counter() - start

    mask = hit.reshape(height, width)
    visibility = np.ones((height, width), dtype=np.float32)
    visibility[mask] = visible
    depth = np.full((height, width), np.inf, dtype=np.float32)
    depth[mask] = (position - eye) @ forward
    position_image = np.full((height, width, 3), np.nan)
    position_image[mask] = position
    normal = np.zeros((height, width, 3), dtype=np.float32)
    normal[mask] = n32
    mesh_id = np.full((height, width), -1, dtype=np.int32)
    mesh_id[mask] = ids
    return ReferenceImage(
        visibility=visibility,
        mask=mask,
        depth=depth,
        position=position_image,
        normal=normal,
        mesh_id=mesh_id,
        samples=k,
        time_first_hits=time_first_hits,
        time_shadow=time_shadow,
        rays=len(lit) * k,
    )


def _facing(normals: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Unit normals (N, 3) float32 flipped against the camera rays' directions."""
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    flip = np.einsum("ij,ij->i", normals, directions) > 0.0
    normals[flip] = -normals[flip]
    return normals.astype(np.float32)


def _first_hits_vector(
    mi: Any, dr: Any, scene: Any, sensor: Any, objects: Sequence[tuple[int, Any]], width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Camera rays through every pixel centre, in batches (vectorized variants).

    Returns the hit flags (W*H,) bool in row-major pixel order, and for the
    hit pixels only: positions (N, 3) float32, camera-facing geometric
    normals (N, 3) float32 and mesh indices (N,) int32.
    """
    hit = np.zeros(width * height, dtype=bool)
    positions, normals, ids = [], [], []
    # A pixel costs about as much as one shadow ray, so the same bound holds.
    step = _rays.MAX_RAYS_PER_BATCH
    for first in range(0, width * height, step):
        pixel = np.arange(first, min(first + step, width * height))
        row, col = np.divmod(pixel, width)
        ray, _weight = sensor.sample_ray(
            time=0.0,
            sample1=0.5,
            sample2=mi.Point2f((col + 0.5) / width, (row + 0.5) / height),
            sample3=mi.Point2f(0.5, 0.5),
        )
        si = scene.ray_intersect(ray)
        valid = np.asarray(si.is_valid().numpy(), dtype=bool)
        hit[pixel] = valid
        positions.append(np.asarray(si.p.numpy(), dtype=np.float32).T[valid])
        d = np.asarray(ray.d.numpy(), dtype=np.float64).T[valid]
        normals.append(_facing(np.asarray(si.n.numpy(), dtype=np.float64).T[valid], d))
        # si.shape is an array of shape pointers: compare it with each mesh's.
        batch_ids = np.full(len(pixel), -1, dtype=np.int32)
        for index, shape in objects:
            batch_ids[np.asarray((si.shape == mi.ShapePtr(shape)).numpy(), dtype=bool)] = index
        ids.append(batch_ids[valid])
    if not positions:
        empty = np.zeros((0, 3), dtype=np.float32)
        return hit, empty, empty, np.zeros(0, dtype=np.int32)
    return hit, np.concatenate(positions), np.concatenate(normals), np.concatenate(ids)


def _first_hits_scalar(
    mi: Any, dr: Any, scene: Any, sensor: Any, objects: Sequence[tuple[int, Any]], width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_first_hits_vector` one pixel per call (scalar variants)."""
    hit = np.zeros(width * height, dtype=bool)
    positions, normals, directions, ids = [], [], [], []
    for pixel in range(width * height):
        row, col = divmod(pixel, width)
        ray, _weight = sensor.sample_ray(
            0.0, 0.5, mi.Point2f((col + 0.5) / width, (row + 0.5) / height), mi.Point2f(0.5, 0.5)
        )
        si = scene.ray_intersect(ray)
        if not si.is_valid():
            continue
        hit[pixel] = True
        positions.append(list(si.p))
        normals.append(list(si.n))
        directions.append(list(ray.d))
        ids.append(next(index for index, shape in objects if si.shape is shape))
    if not positions:
        empty = np.zeros((0, 3), dtype=np.float32)
        return hit, empty, empty, np.zeros(0, dtype=np.int32)
    normal = _facing(np.array(normals, dtype=np.float64), np.array(directions, dtype=np.float64))
    return hit, np.array(positions, dtype=np.float32), normal, np.array(ids, dtype=np.int32)


def _shadow_vector(
    mi: Any,
    dr: Any,
    scene: Any,
    p: np.ndarray,
    n: np.ndarray,
    k: int,
    sampler: Sampler,
    s: np.ndarray | None,
    t: np.ndarray | None,
    targets: np.ndarray | None = None,
) -> np.ndarray:
    """Blocked flags (count * K,) of the shadow rays of ``count`` points.

    ``s`` and ``t`` (count * K,) are the samples' offsets along the light's
    u and v, pixel-major; the sample is ``origin + s u + t v``, a point on a
    rectangular light or a travel direction of a directional one (the ray
    then goes along minus its normalization). Combined in Dr.Jit (float32,
    fused into the tracing kernel). A sphere light passes ``targets``
    (count * K, 3) float32 instead, the samples' world points. The rays are
    spawned by Mitsuba from a SurfaceInteraction3f holding the points' p and n.
    """
    total = len(p) * k
    index = dr.arange(mi.UInt32, total) // k
    si = mi.SurfaceInteraction3f()
    si.p = dr.gather(mi.Point3f, mi.Point3f(np.ascontiguousarray(p.T)), index)
    si.n = dr.gather(mi.Normal3f, mi.Normal3f(np.ascontiguousarray(n.T)), index)
    # A default SurfaceInteraction3f has empty fields; Ray3f needs a time.
    si.time = dr.zeros(mi.Float, total)
    if targets is not None:
        ray = si.spawn_ray_to(mi.Point3f(np.ascontiguousarray(targets.T)))
        return np.asarray(scene.ray_test(ray, coherent=False).numpy(), dtype=bool)
    assert s is not None and t is not None and not isinstance(sampler, _SphereSampler)
    u, v = mi.Vector3f(*sampler.u.tolist()), mi.Vector3f(*sampler.v.tolist())
    sample = mi.Vector3f(*sampler.origin.tolist()) + mi.Float(s) * u + mi.Float(t) * v
    if sampler.directional:
        ray = si.spawn_ray(-dr.normalize(sample))
    else:
        ray = si.spawn_ray_to(mi.Point3f(sample))
    # `coherent` by keyword: positionally, False binds to the `active` mask
    # of the other overload and every ray reports a miss.
    return np.asarray(scene.ray_test(ray, coherent=False).numpy(), dtype=bool)


def _shadow_scalar(
    mi: Any,
    dr: Any,
    scene: Any,
    p: np.ndarray,
    n: np.ndarray,
    k: int,
    sampler: Sampler,
    s: np.ndarray | None,
    t: np.ndarray | None,
    targets: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`_shadow_vector` one ray per call (scalar variants)."""
    blocked = np.empty(len(p) * k, dtype=bool)
    if targets is not None:
        samples = targets
    else:
        assert s is not None and t is not None and not isinstance(sampler, _SphereSampler)
        # The samples in float32, as the vectorized variant computes them.
        origin, u, v = (x.astype(np.float32) for x in (sampler.origin, sampler.u, sampler.v))
        samples = origin + s[:, None] * u + t[:, None] * v
    si = mi.SurfaceInteraction3f()
    si.time = 0.0
    for point in range(len(p)):
        si.p = mi.Point3f(*p[point].tolist())
        si.n = mi.Normal3f(*n[point].tolist())
        for ray_index in range(point * k, (point + 1) * k):
            value = samples[ray_index].tolist()
            if targets is None and sampler.directional:
                ray = si.spawn_ray(-dr.normalize(mi.Vector3f(*value)))
            else:
                ray = si.spawn_ray_to(mi.Point3f(*value))
            blocked[ray_index] = bool(scene.ray_test(ray, coherent=False))
    return blocked
