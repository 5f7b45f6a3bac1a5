"""The result type and the two entry points."""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from . import _validate as check
from . import backend as backends
from .light import RectLight
from .scene import Scene

METHODS = ("ssm", "bitmask", "exact")
# "auto" resolves to one of METHODS (see `auto_settings`); the result names
# the method that ran.
AUTO = "auto"
# Methods that take `samples=`; of them, those that trace the occluder
# triangles (and so make no occluder maps).
SAMPLING_METHODS = ("bitmask", "exact")
TRACING_METHODS = ("exact",)
# Whether the occluder hierarchy is on by default, per occluder-map method:
# off for the paper's method (published without one), on for bitmask.
DEFAULT_HIERARCHY = {"ssm": False, "bitmask": True}
# How "ssm" sums micro-patch occlusions (the others count samples exactly).
PRECISIONS = ("f32", "f64", "f16", "f16-batched")
DEFAULT_SAMPLES = 256  # keep in sync with DEFAULT_SAMPLES in src/methods/mod.rs
MAX_PASSES = 8  # keep in sync with MAX_PASSES in src/pipeline.rs
# The backends a result can come from ("auto" picks one of them).
BACKENDS = tuple(b for b in backends.BACKENDS if b != "auto")


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
    """Front (nearest) occluder depth; None for ``method="exact"``, which traces
    the occluder triangles instead of reading maps."""
    occluder_depth_back: np.ndarray | None
    """Back (farthest) occluder depth; None with one pass or ``"exact"``."""
    light: RectLight
    extent: tuple[float, float]
    """Tangent half-extents (tx, ty)."""
    method: str
    passes: int
    extent_fitted: bool
    """True when ``extent`` was fitted to the shadows (``extent=None``)."""
    timings: dict[str, float] = field(default_factory=dict)
    """Seconds per stage, in the order the stages ran."""
    samples: int | None = None
    """Light samples per receiver (sampling methods), else None."""
    hierarchy: bool | None = None
    """Whether the occluder hierarchy was used (occluder-map methods), else None."""
    precision: str | None = None
    """How ``"ssm"`` summed the occlusions (see ``precision=``), else None."""
    occluder_depth_middle: tuple[np.ndarray, ...] = ()
    """With ``passes`` >= 3, the peeled layers between front and back, nearest
    first: layer k is the nearest surface beyond layer k - 1."""
    _occluder_mesh: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)

    @property
    def resolution(self) -> tuple[int, int]:
        """(W, H)."""
        h, w = self.visibility.shape
        return w, h

    def __repr__(self) -> str:
        w, h = self.resolution
        total = sum(self.timings.values()) * 1e3
        return (
            f"ShadowMap({w}x{h}, method={self.method!r}, passes={self.passes}, "
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

    def sample(self, points: Any, *, outside: float | None = None) -> np.ndarray:
        """Visibility (N,) float32 at world points lying on receivers.

        Each point is shaded with the same method as the map, at its own exact
        position and depth (no interpolation between texels): the occluder maps
        are the occluders. Points outside the map's extent (or at/behind the
        light's plane) get ``outside``; by default that is 1.0 when the extent
        was fitted (no shadow can fall there) and a ValueError otherwise.
        """
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
        if not np.isfinite(pts).all():
            raise ValueError("points: must be finite")
        w, h = self.resolution
        if self.method in TRACING_METHODS:
            ov, of = self._occluder_mesh
            occ = {"occ_vertices": ov, "occ_faces": of}
        else:
            occ = {
                "occluder_depth": self.occluder_depth,
                "occluder_depth_back": self.occluder_depth_back,
                "occluder_depth_middle": list(self.occluder_depth_middle),
            }
        vis, inside = _core.sample_points(
            self.light._core_args(),
            self.extent,
            w,
            h,
            np.ascontiguousarray(pts),
            self.method,
            self.samples,
            self.hierarchy,
            self.precision,
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
        return _core.receiver_points(self.receiver_depth, self.light._core_args(), self.extent)


def _check_samples(samples: Any, method: str) -> int | None:
    if samples is None:
        return None
    samples = check.integer("samples", samples)
    if method not in SAMPLING_METHODS:
        raise ValueError(f"samples: applies to the sampling methods {SAMPLING_METHODS}, not to {method!r}")
    if samples < 1:
        raise ValueError(f"samples: must be >= 1, got {samples}")
    return samples


def auto_settings(resolution: tuple[int, int]) -> tuple[str, tuple[int, int]]:
    """What ``method="auto"`` runs at output ``resolution`` (W, H): the method
    and the occluder maps' resolution.

    The rule comes from the study (``python -m softshadow.study``, table in
    ``docs/study/study.md``): on its four scenes at 256², the point of the
    accuracy-time plane where softshadow is furthest ahead of Mitsuba's
    ``ray_test`` at equal error is the paper's method with two passes and
    occluder maps a quarter of the output's resolution (4.7-8.4x faster, errors
    0.030-0.037); finer occluder maps cost 2.5-8x more for at most 0.005 less
    error. Below 64 texels an occluder map loses small occluders, so the rule
    keeps at least 64 (never more than the output's). For errors near 0.01,
    ask for ``method="bitmask"``.
    """
    return "ssm", tuple(min(n, max(64, n // 4)) for n in resolution)


def _check_precision(precision: Any, method: str, run_on: str) -> str | None:
    if precision is None:
        return "f32" if method == "ssm" else None
    precision = check.choice("precision", precision, PRECISIONS)
    if method != "ssm":
        raise ValueError(f"precision: applies to 'ssm' (sums of occlusions), not to {method!r}")
    if run_on == "gpu" and precision != "f32":
        raise ValueError(f'precision: the GPU backend sums in "f32" only, got {precision!r}; use backend="cpu"')
    return precision


def _check_hierarchy(hierarchy: Any, method: str, run_on: str) -> bool | None:
    if hierarchy is None:
        if method not in DEFAULT_HIERARCHY:
            return None
        # The GPU kernels have no hierarchy yet: off there by default.
        return DEFAULT_HIERARCHY[method] and run_on == "cpu"
    if not isinstance(hierarchy, (bool, np.bool_)):
        raise TypeError(f"hierarchy: must be a bool or None, got {type(hierarchy).__name__}")
    if method not in DEFAULT_HIERARCHY:
        allowed = tuple(DEFAULT_HIERARCHY)
        raise ValueError(f"hierarchy: applies to the occluder-map methods {allowed}, not to {method!r}")
    if hierarchy and run_on == "gpu":
        raise ValueError('hierarchy: the GPU backend has no occluder hierarchy yet; use backend="cpu"')
    return bool(hierarchy)


def soft_shadow_map(
    scene: Scene,
    light: RectLight,
    *,
    resolution: int | tuple[int, int] = 256,
    extent: float | tuple[float, float] | None = None,
    passes: int = 2,
    method: str = "ssm",
    samples: int | None = None,
    occluder_resolution: int | tuple[int, int] | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = "cpu",
) -> ShadowMap:
    """Soft shadow map of ``scene``'s occluders on its receivers.

    Parameters
    ----------
    scene, light
        The geometry and the rectangular area light.
    resolution
        ``int`` for a square map or ``(W, H)``. The occluder and receiver maps
        share it.
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
        front of the light's plane. Tangent half-extents are at most 1e6.
        Geometry at or behind the light's plane casts no shadow (it is
        clipped), and an occluder at or beyond a receiver's depth does not
        shadow that receiver.
    passes
        The occluder depth layers: 1, the front; 2, front and back (§3.5 of
        the paper); 3 to 8, front, ``passes - 2`` layers found by depth
        peeling (each the nearest surface beyond the previous layer), and
        back. ``ssm`` merges the layers' sums by the larger occlusion,
        ``bitmask`` ORs their masks. (Ignored by ``exact``.)
    method
        ``"ssm"``: soft shadow maps as published (Atty et al. 2005).
        ``"bitmask"``: the micro-patches of the occluder maps mark the light
        samples they hide in a bit mask per receiver (``samples``: 16, 64 or
        256, a multi-jittered pattern shared by all receivers); masks merge
        by OR, so overlapping back-projections count once and the two layers
        combine without double counting (Schwarz & Stamminger 2007).
        ``"exact"``: ray casting against the occluder triangles (a BVH) with
        ``samples`` stratified light samples per receiver texel, jittered
        deterministically; converges to the true visibility as the samples
        grow. It reads no occluder maps (``occluder_depth`` is None, and
        ``passes`` does not apply).
        ``"auto"``: the settings that, on the study's scenes, are furthest
        ahead of ray tracing at equal error (see :func:`auto_settings`):
        ``"ssm"`` with occluder maps at a quarter of ``resolution`` (at least
        64) unless ``occluder_resolution`` is given. The result's ``method``
        names the method that ran.
    samples
        Light samples per receiver for ``"bitmask"`` and ``"exact"``
        (default 256, a 16x16 stratification); refused for ``"ssm"``.
    occluder_resolution
        Resolution of the occluder maps, ``int`` or ``(W, H)`` (same extent as
        the output); default: ``resolution``. The SSM's cost grows with the
        square of the occluder texel count per penumbra, so a coarser occluder
        map is much cheaper; its error is the discretization of §4.1.1 (the
        paper notes that large lights need fewer occluder texels).
    hierarchy
        For the occluder-map methods: read the occluder maps through a
        min/max pyramid (2x2 texels per level). Each 8x8 tile of receivers
        skips what cannot reach it and reads the coarsest level whose
        texels, back-projected onto the light from the nearest occluder that
        can reach the tile, cover at most 3% of the light's width: wide
        penumbrae read few coarse texels, contact shadows keep the finest.
        Default: on for ``"bitmask"`` on the CPU, off for ``"ssm"`` (the
        paper's method, reproduced as published) and on the GPU, which has
        no hierarchy yet (``True`` there raises ValueError).
    precision
        How ``"ssm"`` sums the micro-patch occlusions (Appendix A of the
        paper): ``"f32"`` (default; each occluder row is summed on its own
        before joining the total, which keeps the rounding error near
        sqrt(M) eps for M micro-patches: within 1e-4 of ``"f64"`` at 4096²),
        ``"f64"``, ``"f16"`` (the 2005 GPUs' FP16 blending, emulated: every
        contribution rounded to binary16 and added to a binary16 sum, to
        nearest, in rasterization order; fails where a micro-patch hides less
        than about 2^-10 of the light, see ``softshadow.fp16`` and
        docs/precision/fp16.md) and ``"f16-batched"`` (the paper's workaround:
        FP16 sums over batches of about sqrt(M) micro-patches, the batches
        added in f32). Refused for the other methods, which count samples
        exactly. The GPU backend sums in ``"f32"`` (one level) only.
    backend
        ``"cpu"`` (all cores); ``"gpu"``: rasterization, shading and the
        merge of the layers on the GPU (wgpu, Vulkan), for every method, with
        one upload of the set-up triangles (and, for ``"exact"``, of the BVH
        built on the CPU) and one readback. It never falls back: no adapter
        raises ``GpuUnavailableError``. ``"auto"``: the GPU when a real
        (non-software) one is present, else the CPU. ``timings`` then hold the device's stages
        (``gpu_*``, from timestamp queries where the adapter has them).

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
    if not isinstance(light, RectLight):
        raise TypeError(f"light: must be a softshadow.RectLight, got {type(light).__name__}")
    w, h = check.resolution(resolution)
    occ_res = None if occluder_resolution is None else check.resolution(occluder_resolution, "occluder_resolution")
    ext = None if extent is None else check.extent(extent)
    passes = check.integer("passes", passes)
    if not 1 <= passes <= MAX_PASSES:
        raise ValueError(f"passes: must be in [1, {MAX_PASSES}] (occluder depth layers), got {passes}")
    method = check.choice("method", method, (*METHODS, AUTO))
    if method == AUTO:
        method, auto_occ = auto_settings((w, h))
        occ_res = auto_occ if occ_res is None else occ_res
    samples = _check_samples(samples, method)
    run_on = backends.resolve(backend, method)
    hierarchy = _check_hierarchy(hierarchy, method, run_on)
    precision = _check_precision(precision, method, run_on)
    (ov, of), (rv, rf) = scene.occluder_mesh, scene.receiver_mesh
    if occ_res is not None and method in TRACING_METHODS:
        raise ValueError(f"occluder_resolution: {method!r} reads no occluder maps")
    r = _core.shadow_map_from_meshes(
        ov, of, rv, rf, light._core_args(), w, h, ext, passes, method, samples, hierarchy, precision, occ_res, run_on
    )
    if method in SAMPLING_METHODS and samples is None:
        samples = DEFAULT_SAMPLES
    return ShadowMap(
        visibility=r["visibility"],
        receiver_depth=r["receiver_depth"],
        occluder_depth=r["occluder_depth"],
        occluder_depth_back=r["occluder_depth_back"],
        light=light,
        extent=tuple(r["extent"]),
        method=method,
        passes=passes,
        extent_fitted=extent is None,
        timings=dict(r["timings"]),
        samples=samples,
        hierarchy=hierarchy,
        precision=precision,
        occluder_depth_middle=tuple(r["occluder_depth_middle"]),
        _occluder_mesh=(ov, of) if method in TRACING_METHODS else None,
    )


def soft_shadow_map_from_depth(
    occluder_depth: np.ndarray,
    receiver_depth: np.ndarray,
    *,
    light_size: Any,
    extent: Any,
    occluder_depth_back: np.ndarray | None = None,
    method: str = "ssm",
    samples: int | None = None,
    hierarchy: bool | None = None,
    precision: str | None = None,
    backend: str = "cpu",
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
    frame. ``method``, ``samples``, ``hierarchy``, ``precision`` and
    ``backend`` are as for :func:`soft_shadow_map` (``"gpu"``: the maps go up
    once, the shading runs on the device, the visibility comes back).

    Depths may be any float32 value > 0 (subnormal to 3.4e38) or +inf; NaN,
    zero and negative depths are refused (ValueError naming the map). Any
    real float array is accepted (converted to C-contiguous float32); integer
    and complex arrays raise TypeError. ``light_size`` must lie within
    about [1e-30, 1e30] times the receivers' depth, or be (0, 0) for a
    point light (hard shadows).
    """
    rec = check.depth_map("receiver_depth", receiver_depth)
    front = check.depth_map("occluder_depth", occluder_depth)
    back = None
    if occluder_depth_back is not None:
        back = check.depth_map("occluder_depth_back", occluder_depth_back, front.shape, "occluder_depth")
    if np.isscalar(light_size):
        light_size = (light_size, light_size)
    size = check.vector("light_size", light_size, 2)
    if not (all(s > 0 for s in size) or size == (0.0, 0.0)):
        raise ValueError(f"light_size: must be > 0, or (0, 0) for a point light, got {list(size)}")
    ext = check.extent(extent)
    method = check.choice("method", method, (*METHODS, AUTO))
    if method == AUTO:
        method = auto_settings(rec.shape[::-1])[0]
    samples = _check_samples(samples, method)
    run_on = backends.resolve(backend, method)
    hierarchy = _check_hierarchy(hierarchy, method, run_on)
    precision = _check_precision(precision, method, run_on)
    r = _core.shadow_map_from_depth(front, back, rec, size, ext, method, samples, hierarchy, precision, run_on)
    if method in SAMPLING_METHODS and samples is None:
        samples = DEFAULT_SAMPLES
    return ShadowMap(
        visibility=r["visibility"],
        receiver_depth=rec,
        occluder_depth=front,
        occluder_depth_back=back,
        light=RectLight.canonical(size),
        extent=ext,
        method=method,
        passes=1 if back is None else 2,
        extent_fitted=False,
        timings=dict(r["timings"]),
        samples=samples,
        hierarchy=hierarchy,
        precision=precision,
    )
