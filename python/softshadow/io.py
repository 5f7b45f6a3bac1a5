"""Writing maps to EXR (OpenEXR, optional: the ``io`` extra) and PNG (no dependency)."""

from __future__ import annotations

import os
import struct
import zlib
from types import ModuleType
from typing import Any

import numpy as np

from ._extras import require


def _openexr(needed_for: str) -> ModuleType:
    """OpenEXR, or MissingExtraError naming the ``io`` extra (no bare ``No module named``)."""
    return require("OpenEXR", "io", needed_for)


def _as_map(name: str, a: Any) -> np.ndarray:
    arr = np.asarray(a)
    if arr.ndim != 2:
        raise ValueError(f"{name}: must be a 2-D map, got shape {arr.shape}")
    return arr


#: EXR compressions by the name ``compression=`` takes, each lossless:
#: OpenEXR's attribute for it and the first OpenEXR version that reads it.
EXR_COMPRESSIONS = {
    "zip": ("ZIP_COMPRESSION", "1.0"),
    "zstd": ("ZSTD_COMPRESSION", "3.5"),
    "none": ("NO_COMPRESSION", "1.0"),
}


def exr_compression(compression: str) -> Any:
    """OpenEXR's constant for ``compression`` (a key of ``EXR_COMPRESSIONS``),
    or ValueError naming ``compression`` when the name or the installed
    OpenEXR does not have it."""
    OpenEXR = _openexr("EXR compression")

    if compression not in EXR_COMPRESSIONS:
        raise ValueError(f"compression: must be one of {sorted(EXR_COMPRESSIONS)}, got {compression!r}")
    attr, since = EXR_COMPRESSIONS[compression]
    if not hasattr(OpenEXR, attr):
        raise ValueError(
            f"compression: {compression!r} needs OpenEXR >= {since}, "
            f"installed {getattr(OpenEXR, '__version__', 'unknown')}"
        )
    return getattr(OpenEXR, attr)


def write_exr(path: str | os.PathLike[str], channels: dict[str, Any] | Any, *, compression: str = "zip") -> None:
    """Writes one or more (H, W) maps as float32 channels of an EXR file.

    ``channels`` is a map (written as channel ``"Y"``) or a dict of name -> map.
    ``compression`` (lossless): ``"zip"`` (read by every EXR reader),
    ``"zstd"`` (smaller and faster to write; read by OpenEXR 3.5 and later
    only) or ``"none"``. Needs the ``OpenEXR`` package (``pip install softshadow[io]``).
    """
    OpenEXR = _openexr("write_exr")
    mode = exr_compression(compression)
    if not isinstance(channels, dict):
        channels = {"Y": channels}
    data = {k: np.ascontiguousarray(_as_map(f"channels[{k!r}]", v), dtype=np.float32) for k, v in channels.items()}
    shapes = {v.shape for v in data.values()}
    if len(shapes) != 1:
        raise ValueError(f"channels: all maps must share one shape, got {sorted(shapes)}")
    header = {"compression": mode, "type": OpenEXR.scanlineimage}
    folder = os.path.dirname(os.path.abspath(os.fspath(path)))
    if not os.path.isdir(folder):
        raise FileNotFoundError(f"path: folder {folder!r} does not exist")
    OpenEXR.File(header, data).write(os.fspath(path))


def read_exr(path: str | os.PathLike[str]) -> dict[str, np.ndarray]:
    """Reads every channel of an EXR file as arrays. A missing file raises
    FileNotFoundError, one OpenEXR cannot read ValueError (both name it)."""
    OpenEXR = _openexr("read_exr")

    p = os.fspath(path)
    if not os.path.isfile(p):
        raise FileNotFoundError(f"path: no such file {p!r}")
    try:
        with OpenEXR.File(p) as f:
            return {k: np.array(c.pixels) for k, c in f.channels().items()}
    except RuntimeError as e:  # OpenEXR's only error type
        raise ValueError(f"path: {p!r} is not an EXR file OpenEXR can read ({e})") from e


def to_uint8(a: Any, *, lo: float = 0.0, hi: float = 1.0) -> np.ndarray:
    """Maps [lo, hi] to [0, 255] (clipped); non-finite values become 0."""
    x = np.asarray(a, dtype=np.float64)
    x = np.where(np.isfinite(x), (x - lo) / (hi - lo), 0.0)
    return (np.clip(x, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def write_png(path: str | os.PathLike[str], image: Any) -> None:
    """Writes an 8-bit grey (H, W) or RGB (H, W, 3) uint8 image as PNG."""
    png = png_bytes(image)
    with open(path, "wb") as f:
        f.write(png)


def png_bytes(image: Any) -> bytes:
    """An 8-bit grey (H, W) or RGB (H, W, 3) uint8 image encoded as PNG."""
    img = np.ascontiguousarray(image)
    if img.dtype != np.uint8:
        raise TypeError(f"image: must be uint8 (see to_uint8), got {img.dtype}")
    if img.ndim == 2:
        color = 0
    elif img.ndim == 3 and img.shape[2] == 3:
        color = 2
    else:
        raise ValueError(f"image: must be (H, W) or (H, W, 3), got {img.shape}")
    h, w = img.shape[:2]
    raw = b"".join(b"\x00" + img[j].tobytes() for j in range(h))

    def chunk(tag: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, color, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 6))
    png += chunk(b"IEND", b"")
    return png
