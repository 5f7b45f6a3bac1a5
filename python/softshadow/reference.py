"""Ground-truth soft-shadow visibility and images computed with Mitsuba 3.

This module is optional: ``import softshadow`` never imports it, and it needs
the ``reference`` extra (``pip install softshadow[reference]``), i.e. Mitsuba 3
and Dr.Jit. Mitsuba is imported lazily, on the first call that needs it, so
merely importing this module is cheap and never fails.

Conventions (shared with the rest of the package)
-------------------------------------------------
A rectangular light has a ``center`` c, a ``normal`` pointing from the light
into the scene, an ``up`` vector and a ``size`` (sx, sy). Its frame is
``n = normalize(normal)``, ``v = normalize(up - (up.n) n)``, ``u = n x v``;
``sx`` is the full width along u and ``sy`` the full height along v.

The visibility of a point is the fraction of the light's *area* that can be
seen from it (uniform over the rectangle, no cosine weighting), where only the
occluder meshes block light: receivers never cast shadows.

Variant
-------
Mitsuba's variant is process-global. The first call picks ``llvm_ad_rgb`` when
Dr.Jit can load libLLVM >= 16 (older versions crash Dr.Jit) and ``scalar_rgb``
otherwise, and selects it once; see :func:`variant`. The scalar variant traces
one ray per Python call (about a million rays per second), which is fine for
tests but slow for full-resolution references.
"""

from __future__ import annotations

import glob
import math
import os
import re
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "ReferenceScene",
    "TraceStats",
    "render_image",
    "reference_map",
    "variant",
    "visibility_at_points",
]

_INSTALL_HINT = "pip install softshadow[reference]"
#: Environment variable forcing the variant ("llvm_ad_rgb" or "scalar_rgb").
VARIANT_ENV = "SOFTSHADOW_MITSUBA_VARIANT"
_SUPPORTED_VARIANTS = ("llvm_ad_rgb", "scalar_rgb")
_MIN_LLVM_MAJOR = 16
# Where Debian/Ubuntu install versioned LLVM libraries; the newest one wins.
_LLVM_GLOBS = (
    "/usr/lib/x86_64-linux-gnu/libLLVM-[0-9][0-9].so",
    "/usr/lib/aarch64-linux-gnu/libLLVM-[0-9][0-9].so",
    "/usr/lib/llvm-[0-9][0-9]/lib/libLLVM.so",
)
_LLVM_VERSION = re.compile(r"libLLVM-(\d+)\.so$|llvm-(\d+)/lib/libLLVM\.so$")

#: Upper bound on the rays traced by one ``ray_test`` call. Each ray costs
#: roughly 100 bytes across the float64 NumPy set-up and the Dr.Jit buffers,
#: so a batch stays below about half a gigabyte.
MAX_RAYS_PER_BATCH = 1 << 22
# Shadow rays start this fraction of the point-to-sample distance away from the
# point and stop this fraction short of the sample. Occluders and receivers are
# separate meshes, so this only guards against float32 round-off.
_RAY_EPSILON = 1e-4

_variant: str | None = None


# --------------------------------------------------------------------------
# Mitsuba loading and variant selection
# --------------------------------------------------------------------------


def _newest_llvm_library() -> str | None:
    """Return the path of the newest libLLVM >= 16 found on this system."""
    best: tuple[int, str] | None = None
    for pattern in _LLVM_GLOBS:
        for path in glob.glob(pattern):
            match = _LLVM_VERSION.search(path)
            if match is None:
                continue
            major = int(match.group(1) or match.group(2))
            if major >= _MIN_LLVM_MAJOR and (best is None or major > best[0]):
                best = (major, path)
    return None if best is None else best[1]


def _import_mitsuba() -> tuple[Any, Any]:
    """Import ``mitsuba`` and ``drjit`` with a usable LLVM library.

    Dr.Jit reads ``DRJIT_LIBLLVM_PATH`` when it initialises its LLVM backend,
    and by default may pick a system LLVM too old for it (LLVM 15 crashes), so
    the variable is set to the newest libLLVM >= 16 when the user has not set
    it and Dr.Jit is not loaded yet.
    """
    if "DRJIT_LIBLLVM_PATH" not in os.environ and "drjit" not in sys.modules:
        library = _newest_llvm_library()
        if library is not None:
            os.environ["DRJIT_LIBLLVM_PATH"] = library
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        raise ImportError(
            f"softshadow.reference needs Mitsuba 3 and Dr.Jit; install them with `{_INSTALL_HINT}`"
        ) from exc
    return mi, dr


def _llvm_usable(mi: Any, dr: Any) -> bool:
    """Whether the ``llvm_ad_rgb`` variant exists and runs on a safe LLVM."""
    if "llvm_ad_rgb" not in mi.variants():
        return False
    if not dr.has_backend(dr.JitBackend.LLVM):  # also initialises the backend
        return False
    version = getattr(dr.detail, "llvm_version", None)
    if version is None:  # older Dr.Jit without the query: trust the backend
        return True
    return tuple(version())[0] >= _MIN_LLVM_MAJOR


def _choose_variant(mi: Any, dr: Any) -> str:
    """Pick the variant: forced by env, else the active one, else the best."""
    forced = os.environ.get(VARIANT_ENV)
    if forced:
        if forced not in _SUPPORTED_VARIANTS:
            raise ValueError(f"{VARIANT_ENV}={forced!r}: expected one of {_SUPPORTED_VARIANTS}")
        if forced == "llvm_ad_rgb" and not _llvm_usable(mi, dr):
            raise RuntimeError(
                f"{VARIANT_ENV}=llvm_ad_rgb but Dr.Jit cannot use libLLVM >= {_MIN_LLVM_MAJOR}; set DRJIT_LIBLLVM_PATH"
            )
        return forced
    # Respect a supported variant the user already selected in this process.
    if mi.variant() in _SUPPORTED_VARIANTS:
        return mi.variant()
    return "llvm_ad_rgb" if _llvm_usable(mi, dr) else "scalar_rgb"


def _mitsuba() -> tuple[Any, Any]:
    """Return ``(mi, dr)`` with this module's variant active.

    The variant is chosen on the first call and then kept; it is re-activated
    only if other code switched Mitsuba to another variant in between, because
    ``mi.*`` types resolve against the active variant at call time.
    """
    global _variant
    mi, dr = _import_mitsuba()
    if _variant is None:
        _variant = _choose_variant(mi, dr)
    if mi.variant() != _variant:
        mi.set_variant(_variant)
    return mi, dr


def variant() -> str:
    """Return the Mitsuba variant used by this module, selecting it if needed.

    Returns
    -------
    str
        ``"llvm_ad_rgb"`` when Dr.Jit can load libLLVM >= 16, else
        ``"scalar_rgb"``. The environment variable
        ``SOFTSHADOW_MITSUBA_VARIANT`` forces either one; a supported variant
        already active in the process is kept.
    """
    _mitsuba()
    assert _variant is not None
    return _variant


# --------------------------------------------------------------------------
# Input handling
# --------------------------------------------------------------------------


def _vector3(value: Any, name: str) -> np.ndarray:
    """Convert to a finite float64 3-vector or raise naming ``name``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a sequence of 3 numbers") from exc
    if array.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {array.tolist()}")
    return array


def _light_frame(
    light: Any,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float]:
    """Return ``(c, u, v, n, sx, sy)`` in float64 for a rectangular light.

    Independent of the core's frame code on purpose (see _texel_world_points).

    ``light`` is any object with ``center``, ``normal``, ``up`` (3-sequences)
    and ``size`` (2-sequence) attributes.
    """
    for attribute in ("center", "normal", "up", "size"):
        if not hasattr(light, attribute):
            raise TypeError(f"light has no attribute {attribute!r}")
    center = _vector3(light.center, "light.center")
    normal = _vector3(light.normal, "light.normal")
    up = _vector3(light.up, "light.up")
    try:
        size = np.asarray(light.size, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError("light.size must be a sequence of 2 numbers") from exc
    if size.shape != (2,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        raise ValueError(f"light.size must be 2 positive finite numbers, got {size}")
    length = np.linalg.norm(normal)
    if length == 0.0:
        raise ValueError("light.normal must be non-zero")
    n = normal / length
    v = up - np.dot(up, n) * n
    v_length = np.linalg.norm(v)
    if v_length <= 1e-9 * max(np.linalg.norm(up), 1.0):
        raise ValueError("light.up must not be parallel to light.normal")
    v /= v_length
    u = np.cross(n, v)
    return center, u, v, n, float(size[0]), float(size[1])


def _points(points: Any) -> np.ndarray:
    """Validate query points as a finite (N, 3) float64 array."""
    try:
        array = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError("points must be an (N, 3) array of numbers") from exc
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError("points must be finite (found NaN or inf)")
    return array


def _positive_int(value: Any, name: str) -> int:
    """Validate a positive integer (bools are rejected)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an int, got {type(value).__name__}")
    if value <= 0:
        raise ValueError(f"{name} must be positive, got {value}")
    return int(value)


def _seed(value: Any) -> int:
    """Validate an RNG seed (a non-negative int)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"seed must be an int, got {type(value).__name__}")
    if value < 0:
        raise ValueError(f"seed must be non-negative, got {value}")
    return int(value)


def _mesh_arrays(meshes: Any, name: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Normalise meshes to a list of (float32 (n,3) vertices, uint32 (m,3) faces).

    Each mesh is a ``(vertices, faces)`` pair or an object with ``.vertices``
    and ``.faces`` (e.g. ``trimesh.Trimesh``). Meshes without faces are
    dropped, since they cannot block anything.
    """
    if isinstance(meshes, (str, bytes)) or not isinstance(meshes, Sequence):
        raise TypeError(f"{name} must be a list of meshes")
    result = []
    for index, mesh in enumerate(meshes):
        label = f"{name}[{index}]"
        if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
            vertices, faces = mesh.vertices, mesh.faces
        elif isinstance(mesh, (tuple, list)) and len(mesh) == 2:
            vertices, faces = mesh
        else:
            raise TypeError(f"{label} must be a (vertices, faces) pair or have .vertices and .faces")
        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"{label} vertices must be (n, 3), got {vertices.shape}")
        if not np.all(np.isfinite(vertices)):
            raise ValueError(f"{label} vertices must be finite")
        if faces.size == 0:
            continue
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"{label} faces must be (m, 3), got {faces.shape}")
        if not np.issubdtype(faces.dtype, np.integer):
            raise TypeError(f"{label} faces must be integers, got {faces.dtype}")
        if faces.min() < 0 or faces.max() >= len(vertices):
            raise ValueError(f"{label} faces index vertices out of range")
        result.append(
            (
                np.ascontiguousarray(vertices, dtype=np.float32),
                np.ascontiguousarray(faces, dtype=np.uint32),
            )
        )
    return result


# --------------------------------------------------------------------------
# Mitsuba scene construction
# --------------------------------------------------------------------------


def _mitsuba_mesh(mi: Any, name: str, vertices: np.ndarray, faces: np.ndarray, bsdf: Any = None) -> Any:
    """Build a ``mi.Mesh`` from float32 vertices and uint32 faces (no files)."""
    props = mi.Properties()
    if bsdf is not None:
        props["bsdf"] = bsdf
    mesh = mi.Mesh(name, len(vertices), len(faces), props)
    params = mi.traverse(mesh)
    # Use the buffer types Mitsuba exposes, so this works for every variant
    # (drjit.llvm.ad.Float in llvm_*, drjit.scalar.ArrayXf in scalar_*).
    params["vertex_positions"] = type(params["vertex_positions"])(vertices.ravel())
    params["faces"] = type(params["faces"])(faces.ravel())
    params.update()
    return mesh


def _light_to_world(mi: Any, light: Any) -> Any:
    """``to_world`` of a Mitsuba ``rectangle`` matching a softshadow light.

    The rectangle spans [-1, 1]^2 in its local xy plane and emits toward its
    local +z. (u, v, n) is left-handed, so mapping x->u, y->v, z->n would be a
    mirroring transform (negative determinant), leaving the emitting side to
    Mitsuba's handling of reflections. Instead x -> v*sy/2, y -> u*sx/2,
    z -> n is right-handed (v x u = n) and covers the same rectangle.
    """
    c, u, v, n, sx, sy = _light_frame(light)
    matrix = np.eye(4)
    matrix[:3, 0] = v * (sy / 2.0)
    matrix[:3, 1] = u * (sx / 2.0)
    matrix[:3, 2] = n
    matrix[:3, 3] = c
    return mi.ScalarTransform4f(matrix)


# --------------------------------------------------------------------------
# Light sampling
# --------------------------------------------------------------------------


def _grid_shape(samples: int, sx: float, sy: float) -> tuple[int, int]:
    """Return the stratification grid (strata along u, strata along v).

    A sqrt(K) x sqrt(K) grid when K is a perfect square; otherwise a x b with
    a * b = K and a the largest divisor of K not above sqrt(K) (a prime K
    gives 1 x K strips). The longer factor goes along the light's longer side
    so strata stay as square as possible.
    """
    small = math.isqrt(samples)
    while samples % small:
        small -= 1
    large = samples // small
    return (large, small) if sx >= sy else (small, large)


def _shadow_rays(
    points: np.ndarray,
    frame: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float],
    grid: tuple[int, int],
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jittered stratified shadow rays from each point toward the light.

    Returns float32 origins and unit directions of shape (3, N*K) (rows are
    contiguous, ready for Dr.Jit) and maxt of shape (N*K,); rays of point i
    are ``i*K ... i*K + K-1``. Computed in float64, rounded at the end.
    """
    c, u, v, _n, sx, sy = frame
    n_u, n_v = grid
    samples = n_u * n_v
    count = len(points)
    cells_u = np.tile(np.arange(n_u, dtype=np.float64), n_v)  # stratum index
    cells_v = np.repeat(np.arange(n_v, dtype=np.float64), n_u)
    # Point-major draw order, so consecutive batches consume the generator's
    # stream exactly as a single batch would: results don't depend on batching.
    jitter = rng.random((count, samples, 2))
    # Offsets of the samples from the light's center along u and v, (N, K);
    # computed in place to keep the memory of large batches down.
    s = jitter[..., 0]
    s += cells_u
    s *= sx / n_u
    s -= 0.5 * sx
    t = jitter[..., 1]
    t += cells_v
    t *= sy / n_v
    t -= 0.5 * sy
    to_center = c - points  # (N, 3)
    direction = np.empty((3, count, samples))
    for axis in range(3):
        np.multiply(s, u[axis], out=direction[axis])
        direction[axis] += t * v[axis]
        direction[axis] += to_center[:, axis, None]
    distance = np.sqrt(np.einsum("inj,inj->nj", direction, direction))
    # A point exactly on the light would give 0/0; it sees that sample.
    np.maximum(distance, np.finfo(np.float64).tiny, out=distance)
    direction /= distance
    offset = _RAY_EPSILON * distance
    origins = np.empty((3, count * samples), dtype=np.float32)
    for axis in range(3):
        origins[axis] = (points[:, axis, None] + offset * direction[axis]).ravel()
    maxt = ((1.0 - 2.0 * _RAY_EPSILON) * distance).astype(np.float32).ravel()
    return origins, direction.reshape(3, -1).astype(np.float32), maxt


# --------------------------------------------------------------------------
# Reference visibility
# --------------------------------------------------------------------------


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
        points_per_batch = max(1, MAX_RAYS_PER_BATCH // samples)
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


# --------------------------------------------------------------------------
# Eye-view rendering
# --------------------------------------------------------------------------


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
