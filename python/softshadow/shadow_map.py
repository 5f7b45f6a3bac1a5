"""The result type and the two entry points.

Each entry point converts its arguments' types and hands them to ``_core``,
which builds the method config (a typed config, or a name with loose
options), resolves it for the call, checks every value, and runs it on the
chosen backend.
"""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from . import _validate as check
from .lights import DirectionalLight, RectLight
from .methods import MethodConfig
from .plan import Decision as Decision  # re-exported: softshadow.shadow_map.Decision as before
from .plan import Plan, plan_from_core
from .scene import Scene


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
    light: RectLight | DirectionalLight
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

    def _light_args(self) -> tuple[Any, ...]:
        if isinstance(self.light, DirectionalLight):
            assert self.depth_origin is not None and self.depth_range is not None
            return (*self.light._core_args(), self.depth_origin, self.depth_range)
        return self.light._core_args()

    @property
    def resolution(self) -> tuple[int, int]:
        """(W, H)."""
        h, w = self.visibility.shape
        return w, h

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


def soft_shadow_map(
    scene: Scene,
    light: RectLight | DirectionalLight,
    *,
    resolution: int | tuple[int, int] = 256,
    extent: float | tuple[float, float] | None = None,
    method: str | MethodConfig = "ssm",
    backend: str = "cpu",
    threads: int | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: int | tuple[int, int] | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    normal_offset: float | None = None,
    depth_bias: float | None = None,
) -> ShadowMap:
    """Soft shadow map of ``scene``'s occluders on its receivers, or of a
    scene shadowing itself.

    Parameters
    ----------
    scene, light
        The geometry and the light: a rectangle, or a
        :class:`DirectionalLight`, whose maps are orthographic (world
        half-extents; depth from the plane across the light touching the
        scene, ``sm.depth_origin``). With the split scene
        (``Scene(occluders=..., receivers=...)``) occluders shadow receivers
        and nothing shadows itself (the paper's setting). With
        ``Scene(meshes=...)`` every mesh casts and receives: the receiver map
        is the nearest surface seen from the light, and each of its texels is
        shaded at its own surface point as :func:`softshadow.render` shades a
        pixel's (``exact`` with offset shadow rays, the map methods with the
        biases ``normal_offset`` and ``depth_bias``, in texels, and the
        tangent-plane bound; CPU only); ``sample`` is then not available.
    resolution
        ``int`` for a square map or ``(W, H)``. The receiver map shares it, and
        the occluder maps unless the method's ``occluder_resolution`` says
        otherwise.
    extent
        Tangent half-extents ``(tx, ty)`` of the map (a number means both).
        ``None`` fits them to where the occluders' shadows (umbra and penumbra)
        can fall on the receivers: an occluder point at tangent ``x`` and depth
        ``z`` shadows at most ``|x| + (Lx/2)(1/z - 1/z_far)`` away from the
        light's axis, ``z_far`` being the farthest receiver depth; the extent is
        the largest such bound over occluder vertices (exact for triangles), cut
        to the receivers' own extent, or to the occluders' own where that is
        wider (by no more than the largest penumbra reach): the map methods
        see only occluders inside the map, and one just outside the
        receivers can shadow them. Fitting needs every occluder vertex in
        front of the light's plane. Tangent half-extents are at most
        ``softshadow.limits()["max_extent"]``.
        Geometry at or behind the light's plane casts no shadow (it is
        clipped), and an occluder at or beyond a receiver's depth does not
        shadow that receiver.
    method
        A typed config, ``Ssm(...)``, ``Bitmask(...)``, ``Exact(...)`` or
        ``Auto()``, or a method's name (``"ssm"``, ``"bitmask"``, ``"exact"``,
        ``"auto"``) with its options given beside it (``method="bitmask",
        samples=64`` is ``method=Bitmask(samples=64)``). ``"ssm"``: soft shadow
        maps as published (Atty et al. 2005). ``"bitmask"``: the micro-patches
        mark the light samples they hide in a bit mask per receiver, merged by
        OR (Schwarz & Stamminger 2007). ``"exact"``: ray casting against the
        occluder triangles with stratified, deterministically jittered light
        samples. ``"auto"``: ``"ssm"`` with two passes and occluder maps at a
        quarter of ``resolution`` (at least 64), the settings the study found
        furthest ahead of ray tracing at equal error. The result's ``method``
        is the config that ran. :func:`softshadow.capabilities` lists every
        option with its default, limits and the backends that restrict it.
    passes, samples, occluder_resolution, hierarchy, precision
        The options of a method given by name (refused beside a typed config,
        and where they do not apply): ``passes``, the occluder depth layers
        (1, the front; 2, front and back, §3.5; 3 to 8 adds layers found by
        depth peeling; default 2); ``samples``, light samples per receiver
        (``bitmask``: 16, 64, 256 or 1024; ``exact``: up to
        ``limits()["max_samples"]``; default 256);
        ``occluder_resolution``, the occluder maps' resolution (default: the
        output's; coarser maps cost much less, their error is §4.1.1's);
        ``hierarchy``, the occluder min/max pyramid (default on for
        ``bitmask`` on the CPU, off for ``ssm`` and on the GPU, which has
        none); ``precision``, how ``ssm`` sums occlusions (``"f32"``
        two-level sums, ``"f64"``, ``"f16"`` emulated FP16 blending,
        ``"f16-batched"`` the paper's sqrt(M) batches; see
        ``python -m softshadow.experiments.fp16`` and docs/precision/fp16.md).
    backend
        ``"cpu"`` (all cores); ``"gpu"``: rasterization, shading and the
        merge of the layers on the GPU (wgpu, Vulkan), for every method, with
        one upload of the set-up triangles (and, for ``"exact"``, of the BVH
        built on the CPU) and one readback. It never falls back: no adapter
        raises ``GpuUnavailableError``. ``"auto"``: the GPU when a real
        (non-software) one is present, else the CPU. ``timings`` then hold the device's stages
        (``gpu_*``, from timestamp queries where the adapter has them).
        The result's ``backend`` says which ran.
    threads
        Worker threads the core may use for this call (1 to
        ``softshadow.limits()["max_threads"]``); default:
        ``SOFTSHADOW_THREADS`` from the environment, else every core. The
        result does not depend on it.

    The light's size must lie within about [1e-30, 1e30] times the receivers'
    depth (the kernels compute in f32, in a depth unit near the receivers'
    depth, so any scale of scene works), or (0, 0): a point light, whose
    shadow is the hard shadow map the methods converge to.
    Bad values raise ValueError or TypeError naming the argument; a map too
    large to allocate raises :class:`softshadow.TooLargeError` (a ValueError
    and a MemoryError) before allocating; an internal error raises
    RuntimeError and leaves the module usable.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: must be a softshadow.Scene, got {type(scene).__name__}")
    if not isinstance(light, (RectLight, DirectionalLight)):
        raise TypeError(f"light: must be a softshadow.RectLight or DirectionalLight, got {type(light).__name__}")
    ext = None if extent is None else check.pair("extent", extent)
    (ov, of), (rv, rf) = scene.occluder_mesh, scene.receiver_mesh
    loose: dict[str, Any] = dict(
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
    )
    if scene.split:
        if normal_offset is not None or depth_bias is not None:
            raise TypeError("normal_offset: the biases are for scenes shadowing themselves (Scene(meshes=...))")
        r = _core.shadow_map_from_meshes(ov, of, rv, rf, light._core_args(), resolution, ext, method, **loose)
    else:
        r = _core.shadow_map_from_scene(
            ov,
            of,
            light._core_args(),
            resolution,
            ext,
            method,
            normal_offset=normal_offset,
            depth_bias=depth_bias,
            **loose,
        )
    return ShadowMap(
        visibility=r.visibility,
        receiver_depth=r.receiver_depth,
        occluder_depth=r.occluder_depth,
        occluder_depth_back=r.occluder_depth_back,
        light=light,
        extent=r.extent,
        method=r.method,
        extent_fitted=extent is None,
        timings=dict(r.timings),
        occluder_depth_middle=tuple(r.occluder_depth_middle),
        backend=r.backend,
        threads=r.threads,
        _occluder_mesh=(ov, of) if r.occluder_depth is None else None,
        self_shadowing=not scene.split,
        depth_origin=r.depth_origin,
        depth_range=r.depth_range,
        plan=plan_from_core(r.plan, r.method),
    )


def soft_shadow_map_from_depth(
    occluder_depth: np.ndarray,
    receiver_depth: np.ndarray,
    *,
    light_size: Any = None,
    extent: Any,
    angular_size: Any = None,
    occluder_depth_back: np.ndarray | None = None,
    method: str | MethodConfig = "ssm",
    backend: str = "cpu",
    threads: int | None = None,
    passes: int | None = None,
    samples: int | None = None,
    occluder_resolution: int | tuple[int, int] | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
) -> ShadowMap:
    """Soft shadow map from light-view depth maps rendered by the caller.

    The maps follow the package's conventions (see :class:`ShadowMap`): planar
    depth, float, ``inf`` where empty, over one extent. The occluder maps may
    have their own resolution (both of one shape); the output has the
    receiver map's. With
    ``occluder_depth_back`` the result is the two-pass one. ``light_size`` is the
    light's (width, height) in the depth's units; ``extent`` the maps' tangent
    half-extents. The result's ``light`` is the canonical light of that size
    (center at the origin, normal +z, up +y), so ``sample`` takes points in that
    frame. ``method``, its options, ``backend`` and ``threads`` are as
    for :func:`soft_shadow_map` (``passes`` and ``occluder_resolution``, when
    given, must match the maps given) (``"gpu"``: the maps go up
    once, the shading runs on the device, the visibility comes back).

    Depths may be any float32 value > 0 (subnormal to 3.4e38) or +inf; NaN,
    zero and negative depths are refused (ValueError naming the map). Any
    real float array is accepted (converted to C-contiguous float32); integer
    and complex arrays raise TypeError. ``light_size`` must lie within
    about [1e-30, 1e30] times the receivers' depth, or be (0, 0) for a
    point light (hard shadows).

    Orthographic maps of a directional light: pass ``angular_size`` (full
    angles in degrees, see :class:`DirectionalLight`) instead of
    ``light_size``; depths are then distances >= 0 from the depth origin
    along the light's direction (+inf where empty) and ``extent`` the maps'
    half-extents in world units. The result's ``light`` is the directional
    light of that size travelling along +z (up +y), its depth origin at the
    world origin, so ``sample`` takes points in that frame.
    """
    rec = check.depth_map("receiver_depth", receiver_depth)
    front = check.depth_map("occluder_depth", occluder_depth)
    back = None if occluder_depth_back is None else check.depth_map("occluder_depth_back", occluder_depth_back)
    if (light_size is None) == (angular_size is None):
        raise TypeError("light_size: pass either light_size (a rectangle's) or angular_size (a directional light's)")
    size = None if light_size is None else check.pair("light_size", light_size)
    angles = None if angular_size is None else check.pair("angular_size", angular_size)
    ext = check.pair("extent", extent)
    r = _core.shadow_map_from_depth(
        front,
        back,
        rec,
        size,
        ext,
        method,
        angular_size=angles,
        passes=passes,
        samples=samples,
        occluder_resolution=occluder_resolution,
        hierarchy=hierarchy,
        precision=precision,
        backend=backend,
        threads=threads,
    )
    return ShadowMap(
        visibility=r.visibility,
        receiver_depth=rec,
        occluder_depth=front,
        occluder_depth_back=back,
        light=(
            RectLight.canonical(size)
            if size is not None
            else DirectionalLight(direction=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0), angular_size=angles)
        ),
        extent=ext,
        method=r.method,
        extent_fitted=False,
        timings=dict(r.timings),
        backend=r.backend,
        threads=r.threads,
        depth_origin=None if size is not None else (0.0, 0.0, 0.0),
        depth_range=r.depth_range,
    )
