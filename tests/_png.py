"""A PNG reader for the tests: 8-bit grey images decoded with zlib alone,
independently of the writers under test (softshadow.io, pillow)."""

from __future__ import annotations

import struct
import zlib

import numpy as np


def decode_grey_png(data: bytes) -> np.ndarray:
    """An 8-bit grey, non-interlaced PNG's pixels, decoded with zlib alone
    (rows filtered with any of the five PNG filters)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        tag, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        (crc,) = struct.unpack(">I", data[pos + 8 + n : pos + 12 + n])
        assert crc == zlib.crc32(tag + body) & 0xFFFFFFFF
        if tag == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + n
    assert ihdr is not None
    w, h, depth, color, _, _, interlace = ihdr
    assert (depth, color, interlace) == (8, 0, 0), "8-bit grey, not interlaced"
    raw = zlib.decompress(idat)
    out = np.zeros((h, w), np.uint8)
    prev = np.zeros(w, np.int32)
    for j in range(h):
        kind, row = raw[j * (w + 1)], np.frombuffer(raw[j * (w + 1) + 1 : (j + 1) * (w + 1)], np.uint8).astype(np.int32)
        cur = np.zeros(w, np.int32)
        for i in range(w):
            a = cur[i - 1] if i else 0
            b = prev[i]
            c = prev[i - 1] if i else 0
            if kind == 0:
                pred = 0
            elif kind == 1:
                pred = a
            elif kind == 2:
                pred = b
            elif kind == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (row[i] + pred) & 0xFF
        out[j], prev = cur, cur
    return out
