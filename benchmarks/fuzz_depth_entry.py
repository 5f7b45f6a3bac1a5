"""Fuzzes the depth-map entry points with hypothesis (not part of CI).

Targets `softshadow.soft_shadow_map_from_depth`, `ShadowMap.sample` and the
extension's `_core.shadow_map_from_depth`, `_core.sample_points` and
`_core.receiver_points` directly (past the Python checks). Inputs mix valid and
hostile values: shapes from 1x1 up, every float dtype and some integer ones,
NaN, +-inf, zeros, negative zeros, subnormals, 1e-30 to 1e30 depths, extreme
light sizes (point lights included) and extents, odd sample counts,
non-contiguous arrays.

Each call must either return a visibility map of the receiver map's shape,
finite, in [0, 1] and 1 wherever there is no receiver or no occluder in front
of it -- or raise ValueError, TypeError or MemoryError naming an argument. Any
other exception (a Rust panic surfacing as RuntimeError or PanicException
included) fails, and a crash of the process (an abort) ends the run with a
non-zero status.

    python benchmarks/fuzz_depth_entry.py --minutes 10      # as recorded in the README
    python benchmarks/fuzz_depth_entry.py --examples 2000   # a fixed budget instead
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import softshadow as ss
from softshadow import _core

ALLOWED = (ValueError, TypeError, MemoryError)
# Calls that returned a result and calls refused, per target (printed per round).
OUTCOMES: dict[str, int] = {}


def tally(what: str) -> None:
    OUTCOMES[what] = OUTCOMES.get(what, 0) + 1


@st.composite
def mostly(draw, valid, hostile, weight: int = 4):
    """`valid` weight/(weight+1) of the time, else `hostile` (a plain coin:
    hypothesis' own branch choice favours the edges), so that enough calls
    get past the checks to exercise the kernels."""
    coin = draw(st.randoms(use_true_random=True)).random()
    return draw(hostile if coin * (weight + 1) < 1 else valid)


# Valid depths include the extremes the kernels must survive.
valid_depths = st.one_of(
    st.floats(0.5, 8.0, width=32),
    st.just(np.inf),
    st.sampled_from([1e-45, 1e-38, 1e-30, 1e-6, 1e6, 1e30, 3.4e38]),
    st.floats(float(np.float32(1e-30)), float(np.float32(1e30)), width=32),
)
hostile_depths = st.one_of(
    st.sampled_from([-np.inf, np.nan, 0.0, -0.0, -1.0, -1e-45]),
    st.floats(width=32, allow_nan=True, allow_infinity=True),
)
sizes = mostly(
    st.one_of(st.floats(0.01, 4.0), st.sampled_from([1e-20, 1e-9, 1e9, 1e20])),
    st.one_of(
        st.sampled_from([0.0, -1.0, np.nan, np.inf, 1e-300, 1e-45, 1e-35, 1e35, 1e300]),
        st.floats(allow_nan=True, allow_infinity=True),
    ),
)
extents = mostly(
    st.one_of(st.floats(0.01, 50.0), st.sampled_from([1e-30, 1e-9, 1e3, 1e6])),
    st.sampled_from([0.0, -0.5, np.nan, np.inf, 1e-300, 1.5e6, 1e30, 1e300]),
)
dtypes = mostly(
    st.just(np.float32), st.sampled_from([np.float64, np.float16, ">f4", np.int32, np.uint8, np.complex64]), 6
)
samples = mostly(st.sampled_from([16, 64, 256]), st.sampled_from([0, 1, 3, -1, 1 << 20, 2**40]), 8)
methods = mostly(st.sampled_from(["ssm", "bitmask"]), st.sampled_from(["exact", "bogus"]), 12)
# The kernels' options: the hierarchy (map methods) and the summation
# precision (ssm); a wrong one for the method is refused by name.
hierarchies = st.sampled_from([None, False, True])
precisions = mostly(st.sampled_from([None, "f32", "f64", "f16", "f16-batched"]), st.sampled_from(["f8", ""]), 12)
backends = st.sampled_from(["cpu"] * 7 + ["gpu"])


@st.composite
def depth_map(draw, shape=None):
    if shape is None:
        shape = (draw(st.integers(1, 24)), draw(st.integers(1, 24)))
    hostile = draw(st.randoms(use_true_random=True)).random() < 0.1
    elements = st.one_of(valid_depths, hostile_depths) if hostile else valid_depths
    a = draw(hnp.arrays(np.float64, shape, elements=elements))
    dtype = draw(dtypes)
    with np.errstate(all="ignore"):
        a = a.astype(dtype)
    if draw(st.randoms(use_true_random=True)).random() < 0.1 and a.shape[1] > 1:
        wide = np.repeat(a, 2, axis=1)
        a = wide[:, ::2]  # the same values, not C-contiguous
    return a


def check_result(vis: np.ndarray, rec: np.ndarray, occ_layers: list[np.ndarray]) -> None:
    assert vis.shape == rec.shape, (vis.shape, rec.shape)
    assert vis.dtype == np.float32
    assert np.isfinite(vis).all(), "non-finite visibility"
    assert ((vis >= 0) & (vis <= 1)).all(), (vis.min(), vis.max())
    r = rec.astype(np.float64)
    assert (vis[~np.isfinite(r)] == 1).all(), "shadow where there is no receiver"
    # Same shape maps only: no occluder texel nearer than the receiver -> lit.
    if all(o.shape == rec.shape for o in occ_layers):
        nearest = np.min([o.astype(np.float64) for o in occ_layers], axis=0).min()
        if nearest >= np.nanmax(np.where(np.isfinite(r), r, -np.inf), initial=-np.inf):
            assert (vis == 1).all(), "shadow with every occluder behind every receiver"


def allowed(e: BaseException) -> None:
    tally(f"refused {type(e).__name__}")
    if not isinstance(e, ALLOWED):
        raise AssertionError(f"unexpected {type(e).__name__}: {e}") from e
    msg = str(e)
    assert msg.split(":")[0].strip(), f"message names no argument: {msg!r}"


@st.composite
def depth_case(draw):
    rec = draw(depth_map())
    same = draw(st.booleans())
    occ = draw(depth_map(rec.shape if same else None))
    back = draw(mostly(st.one_of(st.none(), depth_map(occ.shape)), depth_map()))
    size = draw(mostly(st.tuples(sizes, sizes), st.just((0.0, 0.0)), 19))  # (0, 0): a point light
    ext = (draw(extents), draw(extents))
    method = draw(methods)
    n = draw(samples) if method == "bitmask" else draw(mostly(st.none(), samples, 8))
    opts = (draw(hierarchies), draw(precisions), draw(backends))
    return rec, occ, back, size, ext, method, n, opts


def run_public(case) -> None:
    rec, occ, back, size, ext, method, n, (hierarchy, precision, backend) = case
    try:
        sm = ss.soft_shadow_map_from_depth(
            occ,
            rec,
            light_size=size,
            extent=ext,
            occluder_depth_back=back,
            method=method,
            samples=n,
            hierarchy=hierarchy,
            precision=precision,
            backend=backend,
        )
    except BaseException as e:  # noqa: BLE001 - the point is to see everything
        allowed(e)
        return
    tally("public ok")
    layers = [sm.occluder_depth] + ([] if sm.occluder_depth_back is None else [sm.occluder_depth_back])
    check_result(sm.visibility, sm.receiver_depth, layers)
    # Sampling at the receiver points gives the map back (same sums).
    pts, idx = sm.receiver_points()
    assert np.isfinite(pts).all()
    if len(idx):
        v = sm.sample(pts, outside=1.0)
        assert np.isfinite(v).all() and ((v >= 0) & (v <= 1)).all()


def run_core(case) -> None:
    rec, occ, back, size, ext, method, n, (hierarchy, precision, backend) = case
    try:
        r = _core.shadow_map_from_depth(occ, back, rec, size, ext, method, n, hierarchy, precision, backend)
    except BaseException as e:  # noqa: BLE001
        allowed(e)
        return
    tally("core ok")
    layers = [occ] + ([] if back is None else [back])
    check_result(r["visibility"], rec, layers)


@st.composite
def points_case(draw):
    occ = draw(depth_map())
    coords = mostly(st.floats(-5, 5), hostile_depths, 8)
    pts = draw(hnp.arrays(np.float64, (draw(st.integers(0, 40)), 3), elements=coords))
    size = draw(mostly(st.tuples(sizes, sizes), st.just((0.0, 0.0)), 19))  # (0, 0): a point light
    ext = (draw(extents), draw(extents))
    w, h = draw(mostly(st.integers(1, 30), st.integers(-1, 0))), draw(st.integers(1, 30))
    method = draw(methods)
    n = draw(samples) if method == "bitmask" else draw(mostly(st.none(), samples, 8))
    return occ, pts, size, ext, w, h, method, n, draw(hierarchies), draw(precisions)


def run_points(case) -> None:
    occ, pts, size, ext, w, h, method, n, hierarchy, precision = case
    light = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), size)
    try:
        v, inside = _core.sample_points(light, ext, w, h, pts, method, n, hierarchy, precision, occluder_depth=occ)
    except BaseException as e:  # noqa: BLE001
        allowed(e)
        return
    tally("points ok")
    assert v.shape == (len(pts),) and inside.shape == (len(pts),)
    assert np.isfinite(v).all() and ((v >= 0) & (v <= 1)).all()
    assert (v[~inside] == 1).all()
    try:
        p, idx = _core.receiver_points(occ, light, ext)
    except BaseException as e:  # noqa: BLE001
        allowed(e)
        return
    assert p.shape == (len(idx), 3) and np.isfinite(p).all()


TARGETS = {
    "public": (depth_case(), run_public),
    "core": (depth_case(), run_core),
    "points": (points_case(), run_points),
}


def _runner(strategy, body, examples: int):
    @settings(max_examples=examples, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(strategy)
    def run(case):
        body(case)

    return run


def fuzz(examples: int) -> int:
    for strategy, body in TARGETS.values():
        _runner(strategy, body, examples)()
    return examples * len(TARGETS)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=None, help="fuzz in rounds until this much time has passed")
    ap.add_argument("--examples", type=int, default=500, help="examples per target per round")
    args = ap.parse_args()
    start = time.time()
    total, rounds = 0, 0
    while True:
        total += fuzz(args.examples)
        rounds += 1
        elapsed = time.time() - start
        print(f"round {rounds}: {total} examples, {elapsed:.0f} s, no failure; outcomes {OUTCOMES}", flush=True)
        if args.minutes is None or elapsed >= 60 * args.minutes:
            break
    print(f"fuzz_depth_entry: {total} examples in {time.time() - start:.0f} s, no crash, no unexpected exception")
    sys.exit(0)


if __name__ == "__main__":
    main()
