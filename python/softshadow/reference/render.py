"""Eye-view images of a scene lit by a rectangular light, rendered by Mitsuba.

An ordinary render with Mitsuba's ``direct`` integrator: direct illumination
only (no interreflection), which is what a shadow algorithm reproduces. The
light is a Mitsuba ``rectangle`` area emitter of constant radiance placed on
the softshadow light (see ``_mitsuba._light_to_world``), every mesh a grey
two-sided diffuse surface, and, unlike the visibility references, every
surface casts shadows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ._inputs import _light_frame, _mesh_arrays, _positive_int, _seed, _vector3
from ._mitsuba import _light_to_world, _mitsuba, _mitsuba_mesh


def render_image(
    occluders: Sequence[Any],
    receivers: Sequence[Any],
    light: Any,
    *,
    camera_origin: Sequence[float],
    camera_target: Sequence[float],
    camera_up: Sequence[float] = (0.0, 1.0, 0.0),
    fov: float = 45.0,
    width: int = 256,
    height: int = 256,
    spp: int = 64,
    radiance: float = 10.0,
    seed: int = 0,
) -> np.ndarray:
    """Render an eye view of the scene lit only by the rectangular light.

    Uses Mitsuba's ``direct`` integrator: direct illumination only (no
    interreflection), which is what a shadow algorithm reproduces. All meshes
    get a grey two-sided diffuse BSDF (reflectance 0.5). Unlike the visibility functions
    this is an ordinary render, so every surface, receivers included, casts
    shadows. Meshes are two-sided (their winding does not matter); the light's
    rectangle emits from its front side only and also blocks rays.

    Parameters
    ----------
    occluders, receivers : list
        Meshes, as for :func:`visibility_at_points`.
    light : object
        Rectangular light (``center``, ``normal``, ``up``, ``size``); emits
        ``radiance`` (grey RGB) from its front side, toward ``normal``.
    camera_origin, camera_target, camera_up : sequence of 3 floats
        Perspective camera placement (``look_at`` convention).
    fov : float, optional
        Horizontal field of view in degrees.
    width, height : int, optional
        Image size in pixels.
    spp : int, optional
        Samples per pixel.
    radiance : float, optional
        Emitted radiance of the light.
    seed : int, optional
        Sampler seed.

    Returns
    -------
    numpy.ndarray, shape (height, width, 3), float32
        Linear RGB radiance.
    """
    width = _positive_int(width, "width")
    height = _positive_int(height, "height")
    spp = _positive_int(spp, "spp")
    seed = _seed(seed)
    if not (math.isfinite(fov) and 0.0 < fov < 180.0):
        raise ValueError(f"fov must be in (0, 180) degrees, got {fov}")
    if not (math.isfinite(radiance) and radiance >= 0.0):
        raise ValueError(f"radiance must be finite and non-negative, got {radiance}")
    origin = _vector3(camera_origin, "camera_origin")
    target = _vector3(camera_target, "camera_target")
    up = _vector3(camera_up, "camera_up")
    if np.allclose(origin, target):
        raise ValueError("camera_origin and camera_target must differ")
    occluder_meshes = _mesh_arrays(occluders, "occluders")
    receiver_meshes = _mesh_arrays(receivers, "receivers")
    _light_frame(light)

    mi, _dr = _mitsuba()
    # Mitsuba's BSDFs are one-sided (black from the back); `twosided` makes the
    # result independent of the meshes' winding.
    grey = {
        "type": "twosided",
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.5}},
    }
    scene: dict[str, Any] = {
        "type": "scene",
        "integrator": {"type": "direct"},
        "sensor": {
            "type": "perspective",
            "fov": float(fov),
            "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=origin.tolist(), target=target.tolist(), up=up.tolist()),
            "sampler": {"type": "independent", "sample_count": spp},
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "pixel_format": "rgb",
                "rfilter": {"type": "box"},
            },
        },
        "light": {
            "type": "rectangle",
            "to_world": _light_to_world(mi, light),
            "emitter": {
                "type": "area",
                "radiance": {"type": "rgb", "value": float(radiance)},
            },
        },
    }
    for prefix, meshes in (("occluder", occluder_meshes), ("receiver", receiver_meshes)):
        for index, (vertices, faces) in enumerate(meshes):
            name = f"{prefix}_{index}"
            scene[name] = _mitsuba_mesh(mi, name, vertices, faces, mi.load_dict(grey))
    image = mi.render(mi.load_dict(scene), spp=spp, seed=seed)
    return np.array(image, dtype=np.float32).reshape(height, width, 3)
