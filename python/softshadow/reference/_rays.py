"""Shadow rays toward a rectangular light: stratified jittered sampling, batching.

The visibility of a point P is estimated with K rays from P to points of the
light: the light's rectangle is cut into a grid of K strata (see
:func:`_grid_shape`) and one uniformly jittered sample is drawn in each, so
the estimate is the fraction of unblocked rays, a multiple of 1/K. Each ray
starts a small fraction of the P-to-sample distance away from P and stops the
same fraction short of the sample.

Points are traced in batches of at most :data:`MAX_RAYS_PER_BATCH` rays. The
jitter is drawn point-major from one NumPy generator, so the result does not
depend on how the points are split into batches.
"""

from __future__ import annotations

import math

import numpy as np

from ._inputs import LightFrame

#: Upper bound on the rays traced by one ``ray_test`` call. Each ray costs
#: roughly 100 bytes across the float64 NumPy set-up and the Dr.Jit buffers,
#: so a batch stays below about half a gigabyte.
MAX_RAYS_PER_BATCH = 1 << 22
# Shadow rays start this fraction of the point-to-sample distance away from the
# point and stop this fraction short of the sample. Occluders and receivers are
# separate meshes, so this only guards against float32 round-off.
_RAY_EPSILON = 1e-4


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


def _stratified_offsets(
    count: int,
    grid: tuple[int, int],
    sx: float,
    sy: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Jittered stratified offsets (s, t) of ``count`` points' light samples.

    ``s`` (along u) and ``t`` (along v), both float64 of shape (count, K) with
    K = n_u * n_v, lie in [-sx/2, sx/2] and [-sy/2, sy/2]: sample k of a point
    is uniform in stratum (k mod n_u, k div n_u) of the n_u x n_v grid over the
    sx x sy rectangle. The jitter is drawn point-major, so consecutive calls
    consume the generator's stream exactly as one call for all the points.
    """
    n_u, n_v = grid
    samples = n_u * n_v
    cells_u = np.tile(np.arange(n_u, dtype=np.float64), n_v)  # stratum index
    cells_v = np.repeat(np.arange(n_v, dtype=np.float64), n_u)
    # Point-major draw order, so consecutive batches consume the generator's
    # stream exactly as a single batch would: results don't depend on batching.
    jitter = rng.random((count, samples, 2))
    # Offsets of the samples from the centre along u and v, (N, K); computed
    # in place to keep the memory of large batches down.
    s = jitter[..., 0]
    s += cells_u
    s *= sx / n_u
    s -= 0.5 * sx
    t = jitter[..., 1]
    t += cells_v
    t *= sy / n_v
    t -= 0.5 * sy
    return s, t


def _shadow_rays(
    points: np.ndarray,
    frame: LightFrame,
    grid: tuple[int, int],
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jittered stratified shadow rays from each point toward the light.

    Returns float32 origins and unit directions of shape (3, N*K) (rows are
    contiguous, ready for Dr.Jit) and maxt of shape (N*K,); rays of point i
    are ``i*K ... i*K + K-1``. Computed in float64, rounded at the end.
    """
    c, u, v, _n, sx, sy = frame
    samples = grid[0] * grid[1]
    count = len(points)
    s, t = _stratified_offsets(count, grid, sx, sy, rng)
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
# Batching
# --------------------------------------------------------------------------


def _points_per_batch(samples: int) -> int:
    """How many points one batch holds at ``samples`` rays per point.

    As many as fit in :data:`MAX_RAYS_PER_BATCH` rays, and at least one.
    Reads the constant at call time, so tests can lower it.
    """
    return max(1, MAX_RAYS_PER_BATCH // samples)
