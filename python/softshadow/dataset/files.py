"""Writing one item's files all-or-nothing, inside ``--out``.

Each file is written to a temporary name beside its final one
(``<name>.tmp-<pid>-<thread>``), flushed to disk, hashed, and only when
every file of the item is there are they renamed (``os.replace``, atomic on
one file system) to their final names. A failure removes the temporary
files it made; a killed process leaves ``*.tmp-*`` files that the next run
sweeps (:func:`sweep_temporaries`). An item is done only once its manifest
line is written, after the renames (:mod:`.manifest`), so a crash between
the two redoes the item (same bytes).
"""

from __future__ import annotations

import hashlib
import os
import threading
from collections.abc import Callable, Iterable

TMP_MARK = ".tmp-"

Writer = Callable[[str], None]
"""Writes a file at the path it is given."""


def inside(root: str, rel: str) -> str:
    """The absolute path of ``rel`` under ``root``; ValueError if it (or a
    link on its way) leads outside ``root``."""
    if os.path.isabs(rel) or "\x00" in rel:
        raise ValueError(f"path: {rel!r} must be relative to --out")
    real_root = os.path.realpath(root)
    path = os.path.realpath(os.path.join(real_root, rel))
    if os.path.commonpath([real_root, path]) != real_root or path == real_root:
        raise ValueError(f"path: {rel!r} leads outside --out {root!r}")
    return path


def sha256_file(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _sync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_item_files(root: str, writers: dict[str, Writer]) -> dict[str, str]:
    """Writes every file (``rel path -> writer``) under ``root`` as described
    above; returns each file's sha256 by relative path."""
    finals = {rel: inside(root, rel) for rel in writers}
    tag = f"{TMP_MARK}{os.getpid()}-{threading.get_ident()}"
    temps: list[str] = []
    try:
        hashes = {}
        for rel, write in writers.items():
            final = finals[rel]
            os.makedirs(os.path.dirname(final), exist_ok=True)
            tmp = final + tag
            temps.append(tmp)
            write(tmp)
            _sync(tmp)
            hashes[rel] = sha256_file(tmp)
        for rel in writers:
            os.replace(finals[rel] + tag, finals[rel])
        temps.clear()
        for folder in {os.path.dirname(p) for p in finals.values()}:
            _sync(folder)
        return hashes
    finally:
        for tmp in temps:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass


def sweep_temporaries(folders: Iterable[str]) -> int:
    """Removes the temporary files (``*.tmp-*``) left in ``folders`` by killed
    writers; returns how many. Only call it while no writer runs."""
    removed = 0
    for folder in folders:
        try:
            names = os.listdir(folder)
        except FileNotFoundError:
            continue
        for name in names:
            if TMP_MARK in name:
                try:
                    os.unlink(os.path.join(folder, name))
                    removed += 1
                except FileNotFoundError:
                    pass
    return removed
