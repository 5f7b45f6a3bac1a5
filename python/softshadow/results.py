"""The results: what the calls of :mod:`softshadow.api` return.

* :class:`ShadowMap`: a light-view soft shadow map and the maps it was
  computed from (:func:`softshadow.soft_shadow_map`,
  :func:`softshadow.soft_shadow_map_from_depth`); ``sm.sample(points)``
  shades world points with the same method.
* :class:`Image`: an eye-view image, its visibility, shaded images and
  G-buffer (:func:`softshadow.render`).
* :class:`Plan` and its :class:`Decision` list: what ``Auto(error=...)`` or
  ``Auto(time=...)`` decided, held by either result (``sm.plan``,
  ``img.plan``).
* :class:`ErrorEstimate`: a result's error measured from exact rays at a
  random subset of its pixels (``img.error_estimate``), the core's class.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from ._core import ErrorEstimate
from .lights import DirectionalLight, Light
from .methods import MethodConfig
from .scene import Camera


@dataclass(frozen=True)
class Decision:
    """One decision of a plan: its name, whether it was taken, and why (the
    number that decided)."""

    name: str
    taken: bool
    why: str


@dataclass(frozen=True)
class Plan:
    """What ``Auto(error=...)`` or ``Auto(time=...)`` decided for a scene, and
    the config that ran. ``print(sm.plan)`` lists the decisions."""

    decisions: tuple[Decision, ...]
    method: MethodConfig
    planned: MethodConfig | None = None
    """The setting the plan chose, where runs checked against the result's
    error estimate replaced it (``method`` is then the last run's, ``exact``;
    both views); ``None`` where no run was replaced."""

    def __str__(self) -> str:
        lines = [f"[{'x' if d.taken else ' '}] {d.name}: {d.why}" for d in self.decisions]
        return "\n".join([*lines, f"ran: {self.method!r}"])


def plan_from_core(
    decisions: Iterable[Any] | None, method: MethodConfig, planned: MethodConfig | None = None
) -> Plan | None:
    """The core's plan (``(name, taken, why)`` triples, or None when nothing
    was planned) as a :class:`Plan`; ``planned`` the setting it chose where
    a run replaced it."""
    if decisions is None:
        return None
    return Plan(tuple(Decision(*d) for d in decisions), method, None if planned == method else planned)


@dataclass(frozen=True, eq=False, repr=False)
class ShadowMap:
    """A soft shadow map and the light-view maps it was computed from.

    All maps have shape (H, W), seen from the light's center along its normal:
    texel ``[j, i]`` has center direction ``n + x u + y v`` with
    ``x = (-1 + 2(i + 1/2)/W) tx`` and ``y = (1 - 2(j + 1/2)/H) ty``. Depths are
    planar (distance from the light's plane along n), float32, ``inf`` where
    nothing is hit.
    """

    visibility: np.ndarray
    """(H, W) float32 in [0, 1]: fraction of the light's area seen from the
    receiver point of each texel; 1 where there is no receiver."""
    receiver_depth: np.ndarray
    occluder_depth: np.ndarray | None
    """Front (nearest) occluder depth; None for methods that read no
    occluder layers (``Exact`` traces the occluder triangles)."""
    occluder_depth_back: np.ndarray | None
    """Back (farthest) occluder depth; None with one pass or no layers."""
    light: Light
    extent: tuple[float, float]
    """Tangent half-extents (tx, ty); for a DirectionalLight, world
    half-extents of the orthographic maps."""
    method: MethodConfig
    """The config that ran: ``"auto"`` resolved, every default filled in."""
    extent_fitted: bool
    """True when ``extent`` was fitted to the shadows (``extent=None``)."""
    timings: dict[str, float] = field(default_factory=dict)
    """Seconds per stage, in the order the stages ran."""
    occluder_depth_middle: tuple[np.ndarray, ...] = ()
    """With ``passes`` >= 3, the peeled layers between front and back, nearest
    first: layer k is the nearest surface beyond layer k - 1."""
    backend: str = "cpu"
    """The backend that ran it: "cpu" or "gpu"."""
    threads: int = 0
    """Worker threads the CPU stages could use."""
    _occluder_mesh: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    depth_origin: tuple[float, float, float] | None = None
    """For a DirectionalLight: a world point on the maps' depth-0 plane (the
    plane across the light's direction touching the scene on its side)."""
    depth_range: float | None = None
    """For a DirectionalLight: the scene's depth range along the light."""
    self_shadowing: bool = False
    """True for the map of a ``Scene(meshes=...)``: every mesh casts and receives."""
    plan: Plan | None = None
    """What ``Auto(error=...)`` or ``Auto(time=...)`` decided (light-view maps
    of a split scene); None for every other method."""
    error_estimate: ErrorEstimate | None = None
    """The map's error estimated from exact rays at a subset of its receiver
    texels (``estimate_error=True``, always for ``Auto`` with a target of a
    split scene), else ``None``; maps from depth have no triangles to trace
    and never have one."""

    def _light_args(self) -> tuple[Any, ...]:
        if isinstance(self.light, DirectionalLight):
            assert self.depth_origin is not None and self.depth_range is not None
            return (*self.light._core_args(), self.depth_origin, self.depth_range)
        return self.light._core_args()

    @property
    def resolution(self) -> tuple[int, int]:
        """(W, H)."""
        h, w = self.visibility.shape[-2:]
        return w, h

    @property
    def lights(self) -> tuple[Light, ...]:
        """The lights, in order (one for a single light)."""
        return self.light if isinstance(self.light, tuple) else (self.light,)

    @property
    def passes(self) -> int | None:
        """Occluder depth layers read (None for methods that read none)."""
        return getattr(self.method, "passes", None)

    def __repr__(self) -> str:
        w, h = self.resolution
        total = sum(self.timings.values()) * 1e3
        return (
            f"ShadowMap({w}x{h}, method={self.method!r}, backend={self.backend!r}, "
            f"extent=({self.extent[0]:.4g}, {self.extent[1]:.4g}), "
            f"visibility in [{float(self.visibility.min()):.3f}, {float(self.visibility.max()):.3f}], "
            f"{total:.1f} ms)"
        )

    def write_exr(self, path: str | os.PathLike[str]) -> None:
        """Writes the visibility (channel ``V``) and the depth maps (``receiver``,
        ``occluder``, ``occluder_back`` with two passes) as one float32 EXR file.
        Needs ``OpenEXR`` (``pip install softshadow[io]``)."""
        from .io import write_exr

        channels = {"V": self.visibility, "receiver": self.receiver_depth}
        if self.occluder_depth is not None:
            channels["occluder"] = self.occluder_depth
        if self.occluder_depth_back is not None:
            channels["occluder_back"] = self.occluder_depth_back
        write_exr(path, channels)

    def sample(self, points: Any, *, outside: float | None = None, threads: int | None = None) -> np.ndarray:
        """Visibility (N,) float32 at world points lying on receivers.

        Each point is shaded with the same method config as the map, at its
        own exact position and depth (no interpolation between texels): the
        occluder maps are the occluders. Points outside the map's extent (or
        at/behind the light's plane) get ``outside``; by default that is 1.0
        when the extent was fitted (no shadow can fall there) and a
        ValueError otherwise. ``threads`` as for :func:`soft_shadow_map`.
        """
        if self.self_shadowing:
            raise ValueError(
                "points: a scene shadowing itself needs each point's normal to shade it without acne; "
                "use softshadow.render, or the map's own texels (sm.visibility)"
            )
        pts = np.asarray(points)
        if pts.dtype.kind not in "fiu":
            raise TypeError(f"points: must be real numbers, got dtype {pts.dtype}")
        pts = pts.astype(np.float64, copy=False)
        if outside is not None:
            # Any number, NaN included (a marker for points off the map).
            if isinstance(outside, bool) or not isinstance(outside, numbers.Real):
                raise TypeError(f"outside: must be a number or None, got {type(outside).__name__}")
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise ValueError(f"points: must have shape (N, 3), got {pts.shape}")
        if self._occluder_mesh is not None:
            ov, of = self._occluder_mesh
            occ: dict[str, Any] = {"occ_vertices": ov, "occ_faces": of}
        else:
            occ = {
                "occluder_depth": self.occluder_depth,
                "occluder_depth_back": self.occluder_depth_back,
                "occluder_depth_middle": list(self.occluder_depth_middle),
            }
        vis, inside = _core.sample_points(
            self._light_args(),
            self.extent,
            self.resolution,
            np.ascontiguousarray(pts),
            self.method,
            threads=threads,
            **occ,
        )
        if not inside.all():
            if outside is None and not self.extent_fitted:
                k = int(np.argmin(inside))
                raise ValueError(
                    f"points: point {k} {pts[k].tolist()} lies outside the map's extent "
                    f"{self.extent}; pass outside= to give such points a value"
                )
            vis[~inside] = 1.0 if outside is None else float(outside)
        return vis

    def receiver_points(self) -> tuple[np.ndarray, np.ndarray]:
        """World points (M, 3) float64 of the texels that have a receiver, and
        their flat texel indices (M,) into ``visibility.ravel()``."""
        return _core.receiver_points(self.receiver_depth, self._light_args(), self.extent)

    def _repr_png_(self) -> bytes | None:
        """The visibility as a small grey PNG, which Jupyter shows for the map:
        ``round(255 V)`` per texel, mid grey (128) where there is no receiver
        (subsampled beyond 512 a side, enlarged below 256; see
        ``softshadow._preview``)."""
        from . import _preview

        return _preview.png(self.visibility, np.isfinite(self.receiver_depth))

    def plot(self, ax: Any = None, *, title: str | None = None) -> Any:
        """Shows the visibility (grey where there is no receiver) with
        matplotlib (the ``plot`` extra); returns the axes."""
        from . import _preview

        surface = np.isfinite(self.receiver_depth)
        return _preview.plot(self.visibility, surface, ax, f"{self.method!r}" if title is None else title, "ShadowMap")


@dataclass(frozen=True, eq=False, repr=False)
class Image:
    """A rendered image: the visibility, the shaded images and the G-buffer
    they were shaded from.

    Arrays have shape (H, W) (row 0 at the top), or (H, W, 3).
    """

    visibility: np.ndarray
    """float32: the fraction of the light (area, or directions of the sun)
    seen from the surface in each pixel; 1 where the pixel sees no surface.
    (H, W) for one light; (L, H, W), one per light in order, when
    :func:`softshadow.render` was given a list of lights."""
    shaded: np.ndarray
    """float32 (H, W, 3) RGB radiance toward the camera, the shadowed
    direct light summed over the lights; 0 where no surface. It weights
    each visible part of the light by its cosine (and 1/r^2) where the
    method weighs its samples (``exact``, ``bitmask``, ``ssm``, ``pcss``),
    else it is ``unshadowed * visibility``, which weights them alike (see
    docs/shading.md for the measured difference)."""
    unshadowed: np.ndarray
    """float32 (H, W, 3) RGB radiance toward the camera without shadows,
    ``albedo / pi * E`` with E the lights' irradiance in closed form, summed
    over the lights; 0 where no surface."""
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
    method: MethodConfig | tuple[MethodConfig, ...]
    """The config that ran (one per light for a list of lights)."""
    camera: Camera
    light: Light | tuple[Light, ...]
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
    error_estimate: ErrorEstimate | None = None
    """The image's error estimated from exact rays at a subset of its pixels
    (``estimate_error=True``, always for ``Auto`` with a target), else
    ``None``."""
    albedo: np.ndarray | None = None
    """float32 (H, W, 3) the diffuse albedo each pixel was shaded with
    (``render``'s ``albedo=``, else the meshes' colours); 0 where no
    surface."""
    parts: tuple[Image, ...] = ()
    """For a list of lights: one image per light, as :func:`softshadow.render`
    returns for that light alone (its visibility (H, W), shading, method,
    maps, plan, timings and error estimate); empty for one light. The image
    itself then holds the lights (``light``) and configs (``method``) as
    tuples, no maps, plan or estimate of its own, and timings summed over
    the parts."""

    @property
    def mask(self) -> np.ndarray:
        """(H, W) bool: the pixel sees a surface."""
        return self.mesh_id >= 0

    @property
    def resolution(self) -> tuple[int, int]:
        """(W, H)."""
        h, w = self.visibility.shape[-2:]
        return w, h

    @property
    def lights(self) -> tuple[Light, ...]:
        """The lights, in order (one for a single light)."""
        return self.light if isinstance(self.light, tuple) else (self.light,)

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
        out: dict[str, np.ndarray] = {}
        if self.visibility.ndim == 3:
            for i, v in enumerate(self.visibility):
                out[f"V.{i}"] = v
        else:
            out["V"] = self.visibility
        for k, c in enumerate("RGB"):
            out[f"shaded.{c}"] = self.shaded[..., k]
        for k, c in enumerate("RGB"):
            out[f"unshadowed.{c}"] = self.unshadowed[..., k]
        if self.albedo is not None:
            for k, c in enumerate("RGB"):
                out[f"albedo.{c}"] = self.albedo[..., k]
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
        as one float32 EXR file (``V.0``, ``V.1``, ... and ``albedo.RGB`` for
        several lights and an albedo).
        Needs ``OpenEXR`` (``pip install softshadow[io]``)."""
        from .io import write_exr

        write_exr(path, self.channels())

    def plot(self, ax: Any = None, *, title: str | None = None) -> Any:
        """Shows the visibility (background grey; for several lights their
        mean) with matplotlib (the ``plot`` extra); returns the axes."""
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Image.plot needs matplotlib: pip install softshadow[plot]") from e
        if ax is None:
            _, ax = plt.subplots()
        shown = np.where(self.mask, self._visibility_shown(), 0.5)
        ax.imshow(shown, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
        ax.set_title(title if title is not None else f"{self.method!r}")
        ax.set_axis_off()
        return ax

    def _repr_png_(self) -> bytes | None:
        """The visibility as a small grey PNG, which Jupyter shows for the
        image: ``round(255 V)`` per pixel (for several lights the mean V),
        mid grey (128) where the pixel sees no surface (subsampled beyond 512
        a side, enlarged below 256; see ``softshadow._preview``)."""
        from . import _preview

        return _preview.png(self._visibility_shown(), self.mask)

    def _visibility_shown(self) -> np.ndarray:
        """(H, W): the visibility, or its mean over several lights."""
        v = self.visibility
        return v if v.ndim == 2 else v.mean(axis=0, dtype=np.float32)
