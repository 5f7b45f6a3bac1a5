"""What the study measures, shared by its parts and the benchmarks: a
measured :class:`Point`, the median time of a call, and Mitsuba's time at a
given error (:mod:`.study` and :mod:`.eye_plane` both use them).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass
class Point:
    """One measured setting: a method, its settings, time and error."""

    scene: str
    method: str
    setting: str
    seconds: float
    error: float


def median_seconds(fn: Callable[[], object], repeats: int) -> float:
    fn()  # warm-up
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def mitsuba_seconds_at(error: float, points: list[Point]) -> tuple[float, bool]:
    """Mitsuba's ray_test time at ``error`` on the scene of ``points``,
    interpolated log-log between its measured sample counts (error ~
    1/sqrt(samples), time ~ samples), and whether that extrapolates."""
    mi = sorted((p.error, p.seconds) for p in points if p.method == "mitsuba")
    le, lt = np.log([m[0] for m in mi]), np.log([m[1] for m in mi])
    outside = not (le[0] <= np.log(error) <= le[-1])
    # Beyond the measured range, extend the last segment's slope.
    i = 0 if np.log(error) < le[0] else max(0, min(len(le) - 2, int(np.searchsorted(le, np.log(error))) - 1))
    slope = (lt[i + 1] - lt[i]) / (le[i + 1] - le[i])
    return float(np.exp(lt[i] + slope * (np.log(error) - le[i]))), outside
