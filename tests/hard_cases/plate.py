"""Closed form of a rectangle parallel to the light over a parallel receiver.

Seen from a receiver point at tangent (x, y) and depth zr, a rectangle
covering tangent [x0, x1] x [y0, y1] at depth zo < zr back-projects onto the
light's plane as k [x0 - x, x1 - x] x k [y0 - y, y1 - y], k = zr zo / (zr - zo);
the occluded fraction is its overlap with the light [-Lx/2, Lx/2] x
[-Ly/2, Ly/2] over Lx Ly. At or beyond the receiver (zo >= zr) it hides
nothing. With the rectangle's edges on texel edges the occluder map holds it
exactly, so the SSM (whose micro-patches then tile the back-projection) is
exact to f32 rounding, and the bitmask to its sample pattern.
"""

from __future__ import annotations

import numpy as np

import softshadow as ss

# The bitmask places each of a rectangle's 4 edges to one fine stratum of its
# multi-jittered pattern: at most 4 x 16 of 256 samples (as in bitmask.rs).
BITMASK_BOUND = 4 * 16 / 256
SSM_BOUND = 2e-5
# PCSS over one plate: every blocker has its depth, so the filter box is the
# back-projection and, the plate on texel edges, the box filter is exact to
# rounding (measured <= 2.4e-7 on both backends) while a box spans at most
# max_taps (the default, PCSS_TAPS) texels per axis. A wider box is sampled by
# that many strata per axis, one tap at each stratum's centre (pcss.rs): a
# step inside a stratum is off by at most half the stratum's share, 0.5/m
# (measured with 32 taps: 0.0038 for a plate at 0.5 from the light, 0.0145
# on a 2000x1 map; with 16: 0.030 there).
PCSS_BOUND = 1e-6
PCSS_TAPS = int(ss.capabilities()["pcss"].options["max_taps"].default)
PCSS_WIDE_BOUND = 0.5 / PCSS_TAPS


def visibility(x, y, rect, zo, zr, lx, ly):
    x0, x1, y0, y1 = rect
    if zo >= zr:
        return np.ones(np.broadcast(x, y).shape)
    k = zr * zo / (zr - zo)

    def overlap(c, lo, hi, half):
        a = np.clip(k * (lo - c), -half, half)
        b = np.clip(k * (hi - c), -half, half)
        return (b - a) / (2 * half)

    return 1.0 - overlap(x, x0, x1, lx / 2) * overlap(y, y0, y1, ly / 2)


def centers(n: int, t: float) -> np.ndarray:
    """Tangent coordinates of n texel centers over [-t, t] (ascending)."""
    return (-1 + 2 * (np.arange(n) + 0.5) / n) * t


def maps(w: int, h: int, ext, rect, zo, zr):
    """Texel-aligned occluder and receiver maps: the rectangle at depth zo
    (texels whose centers fall in it), a receiver plane at zr everywhere.
    Returns (occluder, receiver, x (W,), y (H,)) with y descending (row 0 is +v)."""
    x = centers(w, ext[0])
    y = centers(h, ext[1])[::-1]
    x0, x1, y0, y1 = rect
    inside = ((x > x0) & (x < x1))[None, :] & ((y > y0) & (y < y1))[:, None]
    occ = np.where(inside, np.float32(zo), np.float32(np.inf)).astype(np.float32)
    rec = np.full((h, w), zr, np.float32)
    return occ, rec, x, y


def bound(method: str, box_texels: float = 0.0) -> float:
    """The method's bound on a plate; ``box_texels``: the widest penumbra,
    in texels (pcss samples boxes wider than PCSS_TAPS texels by strata)."""
    if method == "pcss" and box_texels > PCSS_TAPS:
        return PCSS_WIDE_BOUND
    return {"ssm": SSM_BOUND, "bitmask": BITMASK_BOUND, "pcss": PCSS_BOUND}[method]


def box_texels(size: float, zo: float, zr: float, texel: float) -> float:
    """The penumbra's width L (1/zo - 1/zr) in texels of tangent width ``texel``."""
    return size * (1 / zo - 1 / zr) / texel


def backprojection(x, y, rect, zo, zr, lx, ly):
    """The rectangle's back-projection onto the light, clipped to it:
    (x_lo, x_hi, y_lo, y_hi) in light coordinates, per receiver (x, y)."""
    x0, x1, y0, y1 = rect
    k = zr * zo / (zr - zo)
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    return (
        np.clip(k * (x0 - x), -lx / 2, lx / 2),
        np.clip(k * (x1 - x), -lx / 2, lx / 2),
        np.clip(k * (y0 - y), -ly / 2, ly / 2),
        np.clip(k * (y1 - y), -ly / 2, ly / 2),
    )


def area(b, lx, ly):
    """Fraction of the light covered by clipped rectangle b."""
    return np.maximum(b[1] - b[0], 0) * np.maximum(b[3] - b[2], 0) / (lx * ly)


def intersection(a, b):
    return (np.maximum(a[0], b[0]), np.minimum(a[1], b[1]), np.maximum(a[2], b[2]), np.minimum(a[3], b[3]))
