"""``softshadow-dataset check``: which items of an output folder are complete, missing or broken.

For every k below the count in ``dataset.json``: an item the manifest does
not list as done is *missing*; one it lists is *broken* when a file is
absent, its sha256 differs from the manifest's, or it does not open: the
EXR must read with OpenEXR and hold the expected channels at the
resolution in ``dataset.json``, the JSON record must parse and name the
item's k, seed and spec hash, a PNG must start with the PNG signature.

Only item k's own files are read (``items/00000/00000042.exr`` and its
siblings), never through a link: a manifest entry naming another path
(``../../x``) or a file that is a link is reported broken, not opened.
"""

from __future__ import annotations

import json
import os
import stat
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import io as ssio
from .._extras import require
from . import limits as L
from .files import TMP_MARK, file_inside, open_nofollow, sha256_file
from .manifest import read_dataset, read_manifest

SUFFIXES = (".exr", ".json", ".maps.exr", ".png", ".shaded.png")
"""The files an item may have, after its base name."""


@dataclass
class CheckReport:
    count: int
    complete: list[int] = field(default_factory=list)
    missing: list[int] = field(default_factory=list)
    broken: dict[int, str] = field(default_factory=dict)
    failed: dict[int, str] = field(default_factory=dict)
    """Missing items whose last attempt failed, with the error."""
    temporaries: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.missing and not self.broken


def _expected_channels(groups: list[str]) -> list[str]:
    return ["V" if g == "visibility" else g for g in groups]


def check_item(out: str, info: dict[str, Any], k: int, rec: dict[str, Any], *, hashes: bool = True) -> str | None:
    """Why item k is broken, or None if it is sound."""
    files = rec.get("files")
    if not isinstance(files, dict) or not files:
        return "the manifest lists no files"
    base = f"{info['folder']}/{k // int(info.get('shard', L.SHARD)):05d}/{k:0{int(info.get('item_digits', 8))}d}"
    for role in ("exr", "json"):
        if base + "." + role not in files:
            return f"the manifest lacks its .{role} file"
    for rel in files:
        if not isinstance(rel, str) or rel not in {base + s for s in SUFFIXES}:
            escapes = not isinstance(rel, str) or os.path.isabs(rel) or ".." in rel.replace("\\", "/").split("/")
            where = "leads outside --out" if escapes else f"is not one of item {k}'s files"
            return f"the manifest lists {rel!r}, which {where}; not read"
    for rel, digest in files.items():
        try:
            path = file_inside(out, rel)
        except ValueError:
            return f"{rel}: its folder leads outside --out (a link); not read"
        try:
            mode = os.lstat(path).st_mode
        except FileNotFoundError:
            return f"{rel}: missing"
        except OSError as e:
            return f"{rel}: cannot read it ({e.strerror or e})"
        if stat.S_ISLNK(mode):
            return f"{rel}: is a symbolic link (a link in --out is never read: it could lead outside)"
        if not stat.S_ISREG(mode):
            return f"{rel}: not a regular file"
        try:
            if hashes and sha256_file(path, follow=False) != digest:
                return f"{rel}: sha256 differs from the manifest's"
        except OSError as e:
            return f"{rel}: cannot read it ({e.strerror or e})"
        problem = _opens(path, rel, info, k)
        if problem:
            return f"{rel}: {problem}"
    return None


def _read_bytes(path: str, most: int) -> bytes:
    """Up to ``most`` bytes of a file, not through a link."""
    with open(open_nofollow(path, os.O_RDONLY), "rb") as f:
        return f.read(most)


def _opens(path: str, rel: str, info: dict[str, Any], k: int) -> str | None:
    w, h = info["resolution"]
    if rel.endswith(".exr"):
        try:
            channels = ssio.read_exr(path)
        except (ValueError, OSError) as e:
            return f"does not open as EXR ({e})"
        # OpenEXR reads the channels x.R, x.G, x.B as one (H, W, 3) channel x.
        shapes = {tuple(np.shape(v))[:2] for v in channels.values()}
        if rel.endswith(".maps.exr"):
            if not channels or len(shapes) != 1:
                return f"light-view maps of unequal or no shapes {sorted(shapes)}"
            return None
        if shapes != {(h, w)}:
            return f"channel shapes {sorted(shapes)}, expected ({h}, {w})"
        for name in _expected_channels(info["channels"]):
            if not any(c == name or c.startswith(name + ".") for c in channels):
                return f"no {name!r} channel (it has {sorted(channels)})"
        return None
    if rel.endswith(".json"):
        try:
            record = json.loads(_read_bytes(path, 1 << 24).decode("utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            return f"does not open as JSON ({e})"
        if not isinstance(record, dict):
            return "the record is not a JSON object"
        for key, want in (("k", k), ("seed", info["seed"]), ("spec_hash", info["spec_hash"])):
            if record.get(key) != want:
                return f"record's {key} is {record.get(key)!r}, expected {want!r}"
        return None
    if rel.endswith(".png"):
        try:
            if _read_bytes(path, 8) != b"\x89PNG\r\n\x1a\n":
                return "not a PNG file"
        except OSError as e:
            return f"cannot read it ({e.strerror or e})"
        return None
    return None


def check_output(out: str, *, hashes: bool = True) -> CheckReport:
    """Checks every item of the dataset in ``out`` (see the module's docstring)."""
    require("OpenEXR", "dataset", "softshadow-dataset check (it opens every item's EXR)")
    info = read_dataset(out)
    records = read_manifest(out)
    report = CheckReport(count=int(info["count"]))
    for k in range(report.count):
        rec = records.get(k)
        if rec is None or rec.get("status") != "done":
            report.missing.append(k)
            if rec is not None:
                report.failed[k] = str(rec.get("error"))
            continue
        problem = check_item(out, info, k, rec, hashes=hashes)
        if problem is None:
            report.complete.append(k)
        else:
            report.broken[k] = problem
    folder = os.path.join(out, info["folder"])
    if _real_folder(folder):  # a link's folder is not listed: it may lie outside --out
        for sub in sorted(os.listdir(folder)):
            d = os.path.join(folder, sub)
            if _real_folder(d):
                report.temporaries += [f"{info['folder']}/{sub}/{n}" for n in sorted(os.listdir(d)) if TMP_MARK in n]
    return report


def _real_folder(path: str) -> bool:
    try:
        return stat.S_ISDIR(os.lstat(path).st_mode)
    except OSError:
        return False


def ranges(ks: list[int]) -> str:
    """``[0, 1, 2, 5, 7, 8]`` -> ``"0-2,5,7-8"``."""
    parts: list[str] = []
    start = prev = None
    for k in ks:
        if prev is not None and k == prev + 1:
            prev = k
            continue
        if start is not None:
            parts.append(f"{start}" if start == prev else f"{start}-{prev}")
        start = prev = k
    if start is not None:
        parts.append(f"{start}" if start == prev else f"{start}-{prev}")
    return ",".join(parts)


def format_report(r: CheckReport, *, limit: int = 50) -> str:
    lines = [f"{len(r.complete)} of {r.count} items complete, {len(r.missing)} missing, {len(r.broken)} broken"]
    if r.missing:
        lines.append(f"missing: {ranges(r.missing)}")
        for k, err in list(r.failed.items())[:limit]:
            lines.append(f"  item {k} failed: {err}")
    for k, why in list(r.broken.items())[:limit]:
        lines.append(f"broken: item {k}: {why}")
    if len(r.broken) > limit:
        lines.append(f"... and {len(r.broken) - limit} more broken")
    if r.temporaries:
        lines.append(f"{len(r.temporaries)} temporary files of interrupted writes (the next run removes them)")
    return "\n".join(lines)
