"""The eye view: :func:`render` and its :class:`Image`.

A scene seen through a :class:`softshadow.Camera`, every mesh casting and
receiving shadows (its own included), lit by a :class:`RectLight` or a
:class:`DirectionalLight`. The core casts the pixel-centre rays (the
G-buffer), then shades each pixel's surface point with the method:
``exact`` traces shadow rays, the map methods read light-view occluder
maps focused on what the camera sees. See docs/eye_view.md. Every image
also holds the direct lighting of Lambertian surfaces, unshadowed and times
the visibility (``Image.unshadowed``, ``Image.shaded``; docs/shading.md).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from .camera import Camera
from .lights import DirectionalLight, RectLight, _color
from .methods import MethodConfig
from .plan import Plan, plan_from_core
from .scene import Scene


@dataclass(frozen=True, eq=False, repr=False)
class Image:
    """A rendered image: the visibility, the shaded images and the G-buffer
    they were shaded from.

    Arrays have shape (H, W) (row 0 at the top), or (H, W, 3).
    """

    visibility: np.ndarray
    """float32: the fraction of the light (area, or directions of the sun)
    seen from the surface in each pixel; 1 where the pixel sees no surface."""
    shaded: np.ndarray
    """float32 (H, W, 3) RGB radiance toward the camera, ``unshadowed *
    visibility``; 0 where no surface. An approximation of the shadowed
    direct light: the exact one weights each visible part of the light by
    its cosine (and 1/r^2), the visibility weights them alike (see
    docs/shading.md for its measured size)."""
    unshadowed: np.ndarray
    """float32 (H, W, 3) RGB radiance toward the camera without shadows,
    ``albedo / pi * E`` with E the light's irradiance in closed form; 0 where
    no surface."""
    depth: np.ndarray
    """float32 distance along the optical axis; inf where no surface."""
    position: np.ndarray
    """float64 (H, W, 3) world position; NaN where no surface."""
    normal: np.ndarray
    """float32 (H, W, 3) unit geometric normal facing the camera; 0 where none."""
    mesh_id: np.ndarray
    """int32 index into ``scene.meshes``; -1 where no surface."""
    shadow_maps: tuple[np.ndarray, ...]
    """The map methods' light-view occluder layers (front first, back last;
    empty for ``exact``): planar depth from the light, or for the sun
    orthographic depth from ``depth_origin``."""
    map_extent: tuple[float, float] | None
    """Their half-extents: tangents, or world units for the sun."""
    method: MethodConfig
    """The config that ran."""
    camera: Camera
    light: RectLight | DirectionalLight
    timings: dict[str, float] = field(default_factory=dict)
    """Seconds per stage, in the order they ran."""
    backend: str = "cpu"
    threads: int = 0
    depth_origin: tuple[float, float, float] | None = None
    """For the sun: a world point on the maps' depth-0 plane."""
    depth_range: float | None = None
    """For the sun: the scene's depth range along the light."""
    plan: Plan | None = None
    """What ``Auto(error=...)`` decided for the image (``None`` otherwise);
    ``print(img.plan)`` lists the decisions."""

    @property
    def mask(self) -> np.ndarray:
        """(H, W) bool: the pixel sees a surface."""
        return self.mesh_id >= 0

    @property
    def resolution(self) -> tuple[int, int]:
        """(W, H)."""
        h, w = self.visibility.shape
        return w, h

    def __repr__(self) -> str:
        w, h = self.resolution
        total = sum(self.timings.values()) * 1e3
        hit = float(self.mask.mean()) if self.mask.size else 0.0
        return (
            f"Image({w}x{h}, method={self.method!r}, backend={self.backend!r}, "
            f"{hit:.0%} of pixels hit, visibility in [{float(self.visibility.min()):.3f}, "
            f"{float(self.visibility.max()):.3f}], {total:.1f} ms)"
        )

    def channels(self) -> dict[str, np.ndarray]:
        """Every (H, W) channel by name, as :meth:`write_exr` writes them."""
        out: dict[str, np.ndarray] = {"V": self.visibility}
        for k, c in enumerate("RGB"):
            out[f"shaded.{c}"] = self.shaded[..., k]
        for k, c in enumerate("RGB"):
            out[f"unshadowed.{c}"] = self.unshadowed[..., k]
        out["depth"] = self.depth
        for k, axis in enumerate("xyz"):
            out[f"position.{axis}"] = self.position[..., k]
            out[f"normal.{axis}"] = self.normal[..., k]
        out["mesh_id"] = self.mesh_id.astype(np.float32)
        out["mask"] = self.mask.astype(np.float32)
        return out

    def write_exr(self, path: str | os.PathLike[str]) -> None:
        """Writes every channel (``V``, ``shaded.RGB``, ``unshadowed.RGB``,
        ``depth``, ``position.xyz``, ``normal.xyz``, ``mesh_id``, ``mask``)
        as one float32 EXR file.
        Needs ``OpenEXR`` (``pip install softshadow[io]``)."""
        from .io import write_exr

        write_exr(path, self.channels())

    def plot(self, ax: Any = None, *, title: str | None = None) -> Any:
        """Shows the visibility (background grey) with matplotlib (the
        ``plot`` extra); returns the axes."""
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Image.plot needs matplotlib: pip install softshadow[plot]") from e
        if ax is None:
            _, ax = plt.subplots()
        shown = np.where(self.mask, self.visibility, 0.5)
        ax.imshow(shown, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
        ax.set_title(title if title is not None else f"{self.method!r}")
        ax.set_axis_off()
        return ax

    def _repr_png_(self) -> bytes | None:
        """The visibility as a small grey PNG, which Jupyter shows for the
        image: ``round(255 V)`` per pixel, mid grey (128) where the pixel sees
        no surface (subsampled beyond 512 a side, enlarged below 256; see
        ``softshadow._preview``)."""
        from . import _preview

        return _preview.png(self.visibility, self.mask)


def render(
    scene: Scene,
    light: RectLight | DirectionalLight,
    camera: Camera,
    method: str | MethodConfig = "auto",
    *,
    map_resolution: Any = None,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: Any = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = "cpu",
    threads: int | None = None,
    albedo: Any = None,
) -> Image:
    """Renders the visibility and shaded images of ``scene`` under ``light`` seen by ``camera``.

    Every mesh casts and receives shadows, its own included (the far side of
    a closed mesh is in its own umbra). A :class:`RectLight` lights its
    ``n`` side only: points at or behind its plane get 0.

    The image also holds the direct lighting of Lambertian surfaces
    (docs/shading.md): ``unshadowed = albedo / pi * E``, E the irradiance
    from the light's ``radiance`` (or the sun's ``irradiance``) in closed
    form at the pixel's point and geometric normal (facing the camera), and
    ``shaded = unshadowed * visibility``. That product is an approximation:
    the exact shadowed irradiance weights each visible part of the light by
    its cosine (and 1/r^2), the visibility counts them alike; the two agree
    where a pixel is fully lit or in umbra. The shading runs on the CPU
    after the visibility, on every backend.

    method
        A config or name, as for :func:`soft_shadow_map`. ``exact`` traces
        stratified shadow rays from each pixel's surface point, offset off
        the surface as Mitsuba's ``spawn_ray_to`` does. The map methods
        (``ssm``, ``bitmask``, ``auto``) rasterize light-view occluder layers
        of every mesh, focused on what the camera sees, and shade each pixel
        at its own point. ``Auto(error=e)`` plans for the eye view's error
        (mean |V - V_ref| over the pixels, :func:`softshadow.metrics.compare_images`):
        the rule's maps where their measured error is within ``e``, else
        ``exact`` with the samples its measured error law asks for;
        ``img.plan`` says why (docs/methods/auto.md).
    map_resolution
        The light-view maps' (W, H); by default chosen so that a texel
        covers about one pixel's footprint (the median over the image). A
        config's ``occluder_resolution`` overrides it.
    normal_offset, depth_bias
        The map methods' self-shadowing biases in texels (defaults in the
        core, see docs/eye_view.md): the surface point moves
        ``normal_offset`` texels along its normal, then ``depth_bias``
        texels toward the light.
    backend
        ``"cpu"`` (default), ``"gpu"`` or ``"auto"``: on the GPU the first
        hits, the shadow rays, the occluder layers and the gather at the
        pixels' points run on the device, with the same answers (see
        docs/gpu.md; hard lights on the map methods stay on the CPU).
    albedo
        Keyword-only. The meshes' diffuse albedo: a number (grey) or an RGB
        triple for every mesh, or a sequence with one number or triple per
        mesh of ``scene.meshes`` (three numbers are always one RGB triple).
        Values in [0, 1]. Default (``None``): 0.8 grey, the core's default.

    Bad values raise ValueError or TypeError naming the argument.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: must be a softshadow.Scene, got {type(scene).__name__}")
    if not isinstance(light, (RectLight, DirectionalLight)):
        raise TypeError(f"light: must be a softshadow.RectLight or DirectionalLight, got {type(light).__name__}")
    if not isinstance(camera, Camera):
        raise TypeError(f"camera: must be a softshadow.Camera, got {type(camera).__name__}")
    r = _core.render(
        scene.meshes,
        light._core_args(),
        camera,
        method,
        map_resolution=map_resolution,
        normal_offset=None if normal_offset is None else _number("normal_offset", normal_offset),
        depth_bias=None if depth_bias is None else _number("depth_bias", depth_bias),
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
        emission=light._emission(),
        albedo=_color(albedo),
    )
    return Image(
        visibility=r.visibility,
        shaded=r.shaded,
        unshadowed=r.unshadowed,
        depth=r.depth,
        position=r.position,
        normal=r.normal,
        mesh_id=r.mesh_id,
        shadow_maps=tuple(r.shadow_maps),
        map_extent=r.map_extent,
        method=r.method,
        camera=camera,
        light=light,
        timings=dict(r.timings),
        backend=r.backend,
        threads=r.threads,
        depth_origin=r.depth_origin,
        depth_range=r.depth_range,
        plan=plan_from_core(r.plan, r.method),
    )


def _number(name: str, value: Any) -> float:
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: must be a number, got {type(value).__name__}")
    return float(value)
