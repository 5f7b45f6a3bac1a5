"""Eye-view reference shading: Mitsuba 3's ``direct`` integrator through every pixel centre.

:func:`render_direct` renders the scene a :func:`softshadow.render` call
shades, with Mitsuba's own direct-lighting integrator, and returns the
radiance toward the camera per pixel, (H, W, 3) float32: the ground truth of
``Image.shaded`` (whose shadowed irradiance is the unshadowed one times the
visibility, an approximation this measures; see docs/shading.md).

Scene
-----
Every mesh of ``scene.meshes`` is a two-sided Lambertian surface: a
``twosided`` BSDF wrapping a ``diffuse`` one whose ``reflectance`` is the
mesh's albedo (RGB), and no vertex normals, so Mitsuba shades with the
face's geometric normal as softshadow does. ``albedo`` is read as
``softshadow.render`` reads it: a number or an RGB triple for every mesh,
or one number or triple per mesh (three numbers are always one triple);
default 0.8 grey.

Lights
------
* A rectangular light (``center``, ``normal``, ``up``, ``size``,
  ``radiance``) is a one-sided ``area`` emitter of that radiance on a
  ``rectangle`` shape covering the light (``_mitsuba._light_to_world``: its
  local +z, the side Mitsuba's area emitter lights, is the light's ``n``).
* A directional light (``direction``, ``up``, ``angular_size``,
  ``irradiance``) is a ``directional`` emitter of that irradiance along
  ``direction``: a delta direction, so compare with a sun of angular size 0
  or tiny.
* A disk light (``center``, ``normal``, ``radius``, ``radiance``) is a
  one-sided ``area`` emitter on Mitsuba's ``disk`` shape, the unit disk of
  its local xy plane lit toward its local +z (:func:`_disk_to_world`: a
  uniform scale by the radius, a rotation taking +z to the light's ``n``,
  right-handed so that the lit side stays +z's, and the translation to the
  centre). Its back side emits nothing: Mitsuba's area emitter lights only
  the side its shape's normal points to, as softshadow's disk does, so
  points at or behind its plane get no light, as with the rectangle.
* A sphere light (``center``, ``radius``, ``radiance``) is an ``area``
  emitter on Mitsuba's ``sphere`` shape (``center``, ``radius``; outward
  normals, so it lights the outside). Mitsuba samples the cone of its
  visible cap, as the reference visibility does.

The light's kind is told by its attributes, as
:func:`softshadow.reference.render_visibility` tells it: ``direction`` a
directional light, ``radius`` and ``normal`` a disk, ``radius`` alone a
sphere, otherwise a rectangle.

The emitters' shapes are geometry of Mitsuba's scene; softshadow's lights
are not. What that changes:

* Shadow rays: none. A light-sampled ray stops short of its point on the
  emitter (the near side of a sphere), a BSDF-sampled one counts the first
  emitter it meets, and with a single light there is nothing behind the
  emitter to hide, so a sphere never shadows a point it lights.
* Camera rays: with ``hide_emitters`` (set here), Mitsuba 3.9.1's
  ``direct`` integrator lets them through the emitter's shape to the surface
  behind it (measured: a ray through a rectangle, disk or sphere light
  returns the shading of the floor behind it, and a miss where there is
  none), as softshadow, whose lights are not geometry, does. Mitsuba 3's
  earlier ``direct`` integrator only dropped the emission of a directly
  seen emitter and stopped the camera ray on its shape (black): with
  another version, keep the light, a sphere above all, out of the camera's
  view, or mask the pixels whose rays meet it.
* A sphere is opaque and closed: a surface point inside it, or a mesh
  crossing it, is lit by nothing, as softshadow gives it (0 inside).

Pixel centres
-------------
Mitsuba's ``mi.render`` spreads a pixel's samples over its area; softshadow
shades the pixel centre. So the camera rays here are the sensor's
(:func:`camera_sensor`, the same as :func:`render_visibility`'s) at film
position ``((i + 1/2)/W, (j + 1/2)/H)``, each pixel's ray repeated
``samples`` times, and the integrator's ``sample`` is called on them with a
``stratified`` sampler (jittered, so that a second ``seed`` measures the
noise) seeded for that wavefront: each pixel's ``samples`` lanes are one
stratified set of light (and BSDF) samples, as in Mitsuba's own render. The
radiance is their mean. Pixels are processed in batches of at most
``MAX_LANES`` lanes, each batch seeded from ``seed`` and its index.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._inputs import _positive_int, _seed, _vector3
from ._mitsuba import _light_to_world, _mitsuba, _mitsuba_mesh
from .camera import camera_sensor
from .eye import _axis_frame, _radius, _resolution, _scene_meshes

__all__ = ["render_direct"]

#: Lanes (pixels times samples) per call of the integrator: bounds Dr.Jit's
#: arrays to a few hundred MB.
MAX_LANES = 1 << 22
#: The default albedo, as ``softshadow.render``'s (the core's ``DEFAULT_ALBEDO``).
DEFAULT_ALBEDO = 0.8


def _rgb(value: Any, name: str) -> np.ndarray | None:
    """A number or 3 numbers as an RGB float64 array; None if ``value`` is neither."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    if a.shape == ():
        return np.full(3, float(a))
    if a.shape == (3,):
        return a
    return None


def _albedo_per_mesh(albedo: Any, meshes: int) -> np.ndarray:
    """(meshes, 3) albedos in [0, 1], read as ``softshadow.render`` reads them."""
    if albedo is None:
        per_mesh = np.full((meshes, 3), DEFAULT_ALBEDO)
    else:
        one = _rgb(albedo, "albedo")
        if one is not None:
            per_mesh = np.tile(one, (meshes, 1))
        else:
            items = list(albedo) if isinstance(albedo, (list, tuple, np.ndarray)) else None
            if items is None or len(items) != meshes:
                raise ValueError(f"albedo: must be a number, an RGB triple or one per mesh ({meshes} meshes)")
            rows = [_rgb(item, f"albedo[{k}]") for k, item in enumerate(items)]
            for k, row in enumerate(rows):
                if row is None:
                    raise ValueError(f"albedo[{k}]: must be a number or 3 numbers (R, G, B)")
            per_mesh = np.array(rows)
    if not np.all((per_mesh >= 0.0) & (per_mesh <= 1.0)):
        raise ValueError(f"albedo: must be in [0, 1], got {per_mesh.tolist()}")
    return per_mesh


def _emission(light: Any, name: str) -> list[float]:
    value = getattr(light, name, 1.0)
    rgb = _rgb(value, f"light.{name}")
    if rgb is None or not np.all(np.isfinite(rgb)) or np.any(rgb < 0):
        raise ValueError(f"light.{name}: must be a number or 3 numbers, finite and >= 0, got {value!r}")
    return [float(c) for c in rgb]


def _disk_to_world(mi: Any, light: Any) -> Any:
    """``to_world`` of a Mitsuba ``disk`` matching a softshadow disk light.

    Mitsuba's disk is the unit disk of its local xy plane, its normal (and
    lit side) local +z. With n the light's unit normal, (u, v) the pair
    across it of :func:`eye._axis_frame` (``u = n x v``, so ``v x u = n``):
    x -> v R, y -> u R, z -> n R, a rotation and a uniform scale (no mirror,
    no shear), then the translation to the centre.
    """
    center = _vector3(light.center, "light.center")
    normal = _vector3(light.normal, "light.normal")
    radius = _radius(light)
    length = np.linalg.norm(normal)
    if length == 0.0:
        raise ValueError("light.normal must be non-zero")
    n = normal / length
    u, v = _axis_frame(n)
    matrix = np.eye(4)
    matrix[:3, 0] = v * radius
    matrix[:3, 1] = u * radius
    matrix[:3, 2] = n * radius
    matrix[:3, 3] = center
    return mi.ScalarTransform4f(matrix)


def _emitter(mi: Any, light: Any) -> dict[str, Any]:
    """The scene entry of ``light``: a rectangle, a disk or a sphere with an
    area emitter, or a directional emitter."""
    if hasattr(light, "direction"):
        direction = np.asarray(light.direction, dtype=np.float64)
        return {
            "type": "directional",
            "direction": (direction / np.linalg.norm(direction)).tolist(),
            "irradiance": {"type": "rgb", "value": _emission(light, "irradiance")},
        }
    area = {"type": "area", "radiance": {"type": "rgb", "value": _emission(light, "radiance")}}
    if hasattr(light, "radius") and hasattr(light, "normal"):
        return {"type": "disk", "to_world": _disk_to_world(mi, light), "emitter": area}
    if hasattr(light, "radius"):
        center = _vector3(light.center, "light.center")
        return {"type": "sphere", "center": center.tolist(), "radius": _radius(light), "emitter": area}
    return {
        "type": "rectangle",
        "to_world": _light_to_world(mi, light),
        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": _emission(light, "radiance")}},
    }


def render_direct(
    scene: Any,
    light: Any,
    camera: Any,
    *,
    albedo: Any = None,
    samples: int = 1024,
    seed: int = 0,
) -> np.ndarray:
    """Mitsuba's ``direct`` integrator at every pixel centre: (H, W, 3) float32 radiance.

    Parameters
    ----------
    scene : object
        Anything with ``meshes`` (``(vertices, faces)`` pairs or objects with
        ``.vertices`` and ``.faces``), e.g. a :class:`softshadow.Scene`.
    light : softshadow.RectLight, DirectionalLight, DiskLight or SphereLight
        Or any object with their attributes (``radiance`` or
        ``irradiance`` default to 1); see the module docstring for the
        Mitsuba emitter each one becomes.
    camera : softshadow.Camera
        One ray through each pixel centre (:func:`camera_sensor`).
    albedo : optional
        As for :func:`softshadow.render` (default 0.8 grey).
    samples : int
        Integrator samples per pixel (each one light and one BSDF sample,
        combined by multiple importance sampling). Mitsuba's stratified
        sampler rounds it up to a square.
    seed : int
        Seed of the sampler; another seed gives an independent estimate.

    Returns
    -------
    numpy.ndarray, (H, W, 3) float32
        Radiance toward the camera; 0 where the pixel sees no surface.
    """
    meshes = _scene_meshes(scene)
    per_mesh = _albedo_per_mesh(albedo, len(scene.meshes))
    samples = _positive_int(samples, "samples")
    seed = _seed(seed)
    width, height = _resolution(camera)

    mi, dr = _mitsuba()
    if mi.variant().startswith("scalar"):
        raise RuntimeError(
            "render_direct needs Mitsuba's llvm_ad_rgb variant (a wavefront of samples per pixel); "
            f"the active one is {mi.variant()}"
        )
    scene_dict: dict[str, Any] = {"type": "scene", "light": _emitter(mi, light)}
    for index, vertices, faces in meshes:
        bsdf = mi.load_dict(
            {
                "type": "twosided",
                "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": per_mesh[index].tolist()}},
            }
        )
        name = f"mesh_{index}"
        scene_dict[name] = _mitsuba_mesh(mi, name, vertices, faces, bsdf=bsdf)
    mitsuba_scene = mi.load_dict(scene_dict)
    sensor = mi.load_dict(camera_sensor(camera))
    integrator = mi.load_dict({"type": "direct", "emitter_samples": 1, "bsdf_samples": 1, "hide_emitters": True})
    sampler = mi.load_dict({"type": "stratified", "sample_count": samples, "jitter": True})
    spp = int(sampler.sample_count())

    total = width * height
    radiance = np.zeros((total, 3), dtype=np.float64)
    per_batch = max(1, MAX_LANES // spp)
    for batch, first in enumerate(range(0, total, per_batch)):
        count = min(per_batch, total - first)
        lanes = count * spp
        pixel = dr.arange(mi.UInt32, lanes) // spp + first
        row, col = pixel // width, pixel % width
        ray, _weight = sensor.sample_ray_differential(
            time=0.0,
            sample1=0.5,
            sample2=mi.Point2f((mi.Float(col) + 0.5) / width, (mi.Float(row) + 0.5) / height),
            sample3=mi.Point2f(0.5, 0.5),
        )
        sampler.set_samples_per_wavefront(spp)
        # A seed per (seed, batch): batches must not share sample sequences.
        sampler.seed(seed * 0x9E3779B1 % (1 << 31) + batch, lanes)
        color, _valid, _aovs = integrator.sample(mitsuba_scene, sampler, ray)
        values = np.asarray(color.numpy(), dtype=np.float64)
        values = values.T if values.shape[0] == 3 else values
        radiance[first : first + count] = values.reshape(count, spp, 3).mean(axis=1)
    return radiance.reshape(height, width, 3).astype(np.float32)
