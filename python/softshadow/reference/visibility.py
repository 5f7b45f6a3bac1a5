"""Reference visibility: the fraction of a rectangular light seen from points.

The visibility of a point is the fraction of the light's *area* that can be
seen from it (uniform over the rectangle, no cosine weighting), where only the
occluder meshes block light: receivers never cast shadows. It is estimated
with K stratified, jittered shadow rays per point (see ``_rays``), traced by
Mitsuba's ``Scene.ray_test`` against a scene of the occluders alone, so the
estimate is a multiple of 1/K.

:class:`ReferenceScene` builds that scene once for many queries;
:func:`visibility_at_points` answers one query; :func:`reference_map` gives
the visibility of every receiver texel of a light-view map, whose texel
points it recomputes from the map's planar depth independently of the Rust
core.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._inputs import _light_frame, _mesh_arrays, _points, _positive_int, _seed
from ._mitsuba import _mitsuba, _mitsuba_mesh
from ._rays import _grid_shape, _points_per_batch, _shadow_rays


@dataclass(frozen=True)
class TraceStats:
    """Timing of one :meth:`ReferenceScene.visibility` call.

    Attributes
    ----------
    n_points, samples, n_rays : int
        Query size; ``n_rays = n_points * samples``.
    trace_seconds : float
        Wall time spent in Mitsuba: copying rays into Dr.Jit arrays,
        ``Scene.ray_test`` and reading the hit flags back (in the LLVM variant
        the copies are memcpys, negligible next to the traversal).
        Excludes scene construction and the NumPy ray set-up.
    total_seconds : float
        Wall time of the whole call.
    """

    n_points: int
    samples: int
    n_rays: int
    trace_seconds: float
    total_seconds: float

    @property
    def rays_per_second(self) -> float:
        """Shadow-ray throughput of the ``ray_test`` part, rays per second."""
        return self.n_rays / self.trace_seconds if self.trace_seconds > 0 else math.inf


class ReferenceScene:
    """A Mitsuba scene of occluder meshes, built once, queried many times.

    Parameters
    ----------
    occluders : list
        Occluder meshes, each a ``(vertices (n, 3), faces (m, 3) int)`` pair or
        an object with ``.vertices`` and ``.faces`` (e.g. ``trimesh.Trimesh``).
        Only these block light; receivers are not part of the scene.

    Notes
    -----
    Building the scene (BVH construction) happens here, so benchmarks can time
    :meth:`visibility` alone. In the ``llvm_ad_rgb`` variant the first
    :meth:`visibility` call also JIT-compiles Dr.Jit's small kernels (a few
    milliseconds; they are cached in memory and on disk under ``~/.drjit``),
    and its first large NumPy allocations are slower, so time a warm-up call
    separately. :attr:`last_stats` holds the timing of the most recent call;
    ``last_stats.trace_seconds`` is the Mitsuba part to report.
    """

    def __init__(self, occluders: Sequence[Any]) -> None:
        meshes = _mesh_arrays(occluders, "occluders")
        mi, _dr = _mitsuba()
        self._variant: str = mi.variant()
        scene: dict[str, Any] = {"type": "scene"}
        for index, (vertices, faces) in enumerate(meshes):
            name = f"occluder_{index}"
            scene[name] = _mitsuba_mesh(mi, name, vertices, faces)
        self._scene = mi.load_dict(scene)
        self.n_meshes = len(meshes)
        self.n_triangles = sum(len(faces) for _, faces in meshes)
        self.last_stats: TraceStats | None = None

    @property
    def variant(self) -> str:
        """The Mitsuba variant the scene was built with."""
        return self._variant

    def visibility(self, light: Any, points: Any, *, samples: int = 1024, seed: int = 0) -> np.ndarray:
        """Fraction of the light's area visible from each point.

        Parameters
        ----------
        light : object
            Rectangular light with ``center``, ``normal``, ``up`` and ``size``.
        points : array_like, shape (N, 3)
            Finite query points (on receivers).
        samples : int, optional
            Light samples per point, K, stratified on a grid over the light
            and jittered independently per point: sqrt(K) x sqrt(K) for a
            perfect square K, otherwise a x b with a * b = K, a the largest
            divisor of K not above sqrt(K) (the larger count along the
            light's longer side; a prime K gives K strips).
        seed : int, optional
            Seed of the NumPy generator drawing the jitter; the result is
            deterministic for a given seed and does not depend on batching.

        Returns
        -------
        numpy.ndarray, shape (N,), float32
            Visibility in [0, 1], a multiple of 1/K.
        """
        start = time.perf_counter()
        frame = _light_frame(light)
        points = _points(points)
        samples = _positive_int(samples, "samples")
        rng = np.random.default_rng(_seed(seed))
        grid = _grid_shape(samples, frame[4], frame[5])
        mi, _dr = _mitsuba()  # the variant is chosen once, so it is still ours

        visibility = np.empty(len(points), dtype=np.float32)
        points_per_batch = _points_per_batch(samples)
        trace_seconds = 0.0
        for first in range(0, len(points), points_per_batch):
            batch = points[first : first + points_per_batch]
            origins, directions, maxt = _shadow_rays(batch, frame, grid, rng)
            trace_start = time.perf_counter()
            hits = self._trace(mi, origins, directions, maxt)
            trace_seconds += time.perf_counter() - trace_start
            blocked = hits.reshape(len(batch), samples).mean(axis=1)
            visibility[first : first + len(batch)] = 1.0 - blocked
        self.last_stats = TraceStats(
            n_points=len(points),
            samples=samples,
            n_rays=len(points) * samples,
            trace_seconds=trace_seconds,
            total_seconds=time.perf_counter() - start,
        )
        return visibility

    def _trace(self, mi: Any, origins: np.ndarray, directions: np.ndarray, maxt: np.ndarray) -> np.ndarray:
        """Run ``ray_test`` on a batch of rays; return the hit flags (bool)."""
        if self._variant.startswith("scalar"):
            return self._trace_scalar(mi, origins, directions, maxt)
        ray = mi.Ray3f(
            mi.Point3f(*(mi.Float(row) for row in origins)),
            mi.Vector3f(*(mi.Float(row) for row in directions)),
        )
        ray.maxt = mi.Float(maxt)
        # `coherent` must be passed by keyword: positionally, False binds to
        # the `active` mask of the other overload and every ray reports a miss.
        hits = self._scene.ray_test(ray, coherent=False)
        return np.asarray(hits.numpy(), dtype=bool)

    def _trace_scalar(self, mi: Any, origins: np.ndarray, directions: np.ndarray, maxt: np.ndarray) -> np.ndarray:
        """Scalar-variant fallback: one Python call per ray (~1e6 rays/s)."""
        hits = np.empty(len(maxt), dtype=bool)
        for index in range(len(maxt)):
            ray = mi.Ray3f(
                mi.Point3f(*origins[:, index].tolist()),
                mi.Vector3f(*directions[:, index].tolist()),
            )
            ray.maxt = float(maxt[index])
            hits[index] = bool(self._scene.ray_test(ray, coherent=False))
        return hits


def visibility_at_points(
    occluders: Sequence[Any] | ReferenceScene,
    light: Any,
    points: Any,
    *,
    samples: int = 1024,
    seed: int = 0,
) -> np.ndarray:
    """Reference visibility of points lit by a rectangular light.

    Convenience wrapper building a :class:`ReferenceScene` and calling
    :meth:`ReferenceScene.visibility` once; use the class directly to time
    the ray tracing.

    Parameters
    ----------
    occluders : list or ReferenceScene
        Occluder meshes: ``(vertices, faces)`` pairs or objects with
        ``.vertices`` and ``.faces``; or an already built
        :class:`ReferenceScene`, which is reused.
    light : object
        Rectangular light with ``center``, ``normal``, ``up`` and ``size``.
    points : array_like, shape (N, 3)
        Query points.
    samples : int, optional
        Stratified light samples per point.
    seed : int, optional
        Seed of the jitter.

    Returns
    -------
    numpy.ndarray, shape (N,), float32
        Fraction of the light's area visible from each point.
    """
    # Validate the cheap arguments before building the scene.
    points = _points(points)
    _light_frame(light)
    _positive_int(samples, "samples")
    _seed(seed)
    if not isinstance(occluders, ReferenceScene):
        occluders = ReferenceScene(occluders)
    return occluders.visibility(light, points, samples=samples, seed=seed)


def _texel_world_points(light: Any, extent: Any, depth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World points of receiver texels of a light-view map.

    Texel [j, i] of an (H, W) map looks along ``n + x u + y v`` with
    ``x = (-1 + 2 (i + 0.5) / W) tx`` and ``y = (1 - 2 (j + 0.5) / H) ty``;
    its point is ``c + depth * (n + x u + y v)`` (planar depth).

    Deliberately written again here rather than taken from the Rust light-space
    module: a reference that shared the code under test would follow a flipped
    axis or a wrong extent in it, and the comparison would not see the error.

    Returns
    -------
    points : numpy.ndarray, shape (M, 3), float64
        Points of the texels with a receiver, in row-major texel order.
    mask : numpy.ndarray, shape (H, W), bool
        Where the map has a receiver (finite depth).
    """
    c, u, v, n, _sx, _sy = _light_frame(light)
    extent = np.asarray(extent, dtype=np.float64)
    if extent.shape != (2,) or not np.all(np.isfinite(extent)) or np.any(extent <= 0):
        raise ValueError(f"extent must be 2 positive finite numbers, got {extent}")
    tx, ty = extent
    height, width = depth.shape
    x = (-1.0 + 2.0 * (np.arange(width) + 0.5) / width) * tx
    y = (1.0 - 2.0 * (np.arange(height) + 0.5) / height) * ty
    mask = np.isfinite(depth)
    rows, cols = np.nonzero(mask)
    d = depth[rows, cols][:, None]
    points = c + d * (n + x[cols, None] * u + y[rows, None] * v)
    return points, mask


def _receiver_depth(shadow_map: Any) -> np.ndarray:
    """Validate ``shadow_map.receiver_depth``: (H, W), positive or +inf."""
    depth = np.asarray(shadow_map.receiver_depth, dtype=np.float64)
    if depth.ndim != 2:
        raise ValueError(f"shadow_map.receiver_depth must be 2-D (H, W), got {depth.shape}")
    if np.any(np.isnan(depth)):
        raise ValueError("shadow_map.receiver_depth contains NaN")
    if np.any(depth <= 0):  # also rejects -inf
        raise ValueError("shadow_map.receiver_depth must be positive (inf where no receiver)")
    return depth


def reference_map(
    shadow_map: Any,
    occluders: Sequence[Any] | ReferenceScene,
    *,
    samples: int = 1024,
    seed: int = 0,
) -> np.ndarray:
    """Reference visibility of every receiver texel of a light-view map.

    Parameters
    ----------
    shadow_map : object
        Anything with ``.light`` (a rectangular light), ``.extent`` (tx, ty)
        and ``.receiver_depth`` ((H, W) planar depth, ``inf`` where no
        receiver), e.g. a soft shadow map.
    occluders : list or ReferenceScene
        Occluder meshes, as for :func:`visibility_at_points`.
    samples : int, optional
        Stratified light samples per texel.
    seed : int, optional
        Seed of the jitter.

    Returns
    -------
    numpy.ndarray, shape (H, W), float32
        Visibility of each texel's receiver point; 1.0 where no receiver.
    """
    for attribute in ("light", "extent", "receiver_depth"):
        if not hasattr(shadow_map, attribute):
            raise TypeError(f"shadow_map has no attribute {attribute!r}")
    depth = _receiver_depth(shadow_map)
    points, mask = _texel_world_points(shadow_map.light, shadow_map.extent, depth)
    result = np.ones(depth.shape, dtype=np.float32)
    if len(points):
        result[mask] = visibility_at_points(occluders, shadow_map.light, points, samples=samples, seed=seed)
    return result
