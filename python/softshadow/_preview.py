"""Previews of results for notebooks: the small PNG that Jupyter shows for a
:class:`~softshadow.ShadowMap` or an :class:`~softshadow.Image`
(``_repr_png_``), and their matplotlib ``plot()``.

The PNG is 8-bit grey, one pixel per texel or pixel: visibility V in [0, 1]
maps to ``round(255 V)`` (NaN to 0), and where there is no surface (no
receiver, or a pixel that sees nothing) the value is :data:`BACKGROUND`, the
same mid grey as ``plot()``'s. Arrays whose longer side exceeds
:data:`MAX_SIDE` are subsampled by the smallest integer step that fits
(every ``step``-th row and column, values unchanged); those whose longer
side is under :data:`MIN_SIDE` are enlarged by the largest integer factor
that keeps it within :data:`MIN_SIDE` (each value repeated), so that a 32 x
32 map is not a speck. Encoded with Pillow when it is installed, else with
:func:`softshadow.io.png_bytes` (zlib only).
"""

from __future__ import annotations

import io as _io
from typing import Any

import numpy as np

from .io import png_bytes, to_uint8

#: The grey level (0-255) of "no surface"; ``plot()`` shows it as 0.5.
BACKGROUND = 128
#: The preview's longest side at most (larger arrays are subsampled).
MAX_SIDE = 512
#: Smaller arrays are enlarged by an integer factor up to this side.
MIN_SIDE = 256


def preview_pixels(visibility: np.ndarray, surface: np.ndarray) -> np.ndarray:
    """The preview's (h, w) uint8 grey levels (see the module docstring)."""
    grey = np.where(surface, to_uint8(visibility), np.uint8(BACKGROUND)).astype(np.uint8)
    side = max(grey.shape) if grey.size else 0
    if side > MAX_SIDE:
        step = -(-side // MAX_SIDE)
        grey = grey[::step, ::step]
    elif 0 < side < MIN_SIDE:
        k = MIN_SIDE // side
        if k > 1:
            grey = np.repeat(np.repeat(grey, k, axis=0), k, axis=1)
    return np.ascontiguousarray(grey)


def png(visibility: np.ndarray, surface: np.ndarray) -> bytes | None:
    """The preview as PNG bytes; None for an empty array (Jupyter then shows
    the repr)."""
    grey = preview_pixels(visibility, surface)
    if grey.size == 0:
        return None
    try:
        from PIL import Image as _PILImage
    except ImportError:
        return png_bytes(grey)
    buf = _io.BytesIO()
    _PILImage.fromarray(grey).save(buf, format="PNG")  # uint8 (h, w): mode "L"
    return buf.getvalue()


def plot(visibility: np.ndarray, surface: np.ndarray, ax: Any, title: str, what: str) -> Any:
    """Shows the visibility (0.5 grey where no surface) with matplotlib on
    ``ax`` (a new figure's axes when None); returns the axes."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(f"{what}.plot needs matplotlib: pip install softshadow[plot]") from e
    if ax is None:
        _, ax = plt.subplots()
    shown = np.where(surface, visibility, 0.5)
    ax.imshow(shown, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
    ax.set_title(title)
    ax.set_axis_off()
    return ax
