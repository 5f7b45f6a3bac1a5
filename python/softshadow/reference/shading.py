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
  The rectangle is a shape of the scene: it blocks the camera rays that
  reach it (the integrator hides its emission, ``hide_emitters``) and the
  shadow rays behind it, which our lights do not.
* A directional light (``direction``, ``up``, ``angular_size``,
  ``irradiance``) is a ``directional`` emitter of that irradiance along
  ``direction``: a delta direction, so compare with a sun of angular size 0
  or tiny.

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

from ._inputs import _positive_int, _seed
from ._mitsuba import _light_to_world, _mitsuba, _mitsuba_mesh
from .camera import camera_sensor
from .eye import _resolution, _scene_meshes

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


def _emitter(mi: Any, light: Any) -> dict[str, Any]:
    """The scene entry of ``light``: a rectangle with an area emitter, or a directional emitter."""
    if hasattr(light, "direction"):
        direction = np.asarray(light.direction, dtype=np.float64)
        return {
            "type": "directional",
            "direction": (direction / np.linalg.norm(direction)).tolist(),
            "irradiance": {"type": "rgb", "value": _emission(light, "irradiance")},
        }
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
    light : softshadow.RectLight or softshadow.DirectionalLight
        Or any object with their attributes (``radiance`` or
        ``irradiance`` default to 1).
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
