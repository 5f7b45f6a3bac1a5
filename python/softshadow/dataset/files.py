"""Writing one item's files all-or-nothing, inside ``--out``.

Each file is written to a temporary name beside its final one
(``<name>.tmp-<pid>-<thread>``), flushed to disk, hashed, and only when
every file of the item is there are they renamed (``os.replace``, atomic on
one file system) to their final names. A failure removes the temporary
files it made; a killed process leaves ``*.tmp-*`` files that the next run
sweeps (:func:`sweep_temporaries`). An item is done only once its manifest
line is written, after the renames (:mod:`.manifest`), so a crash between
the two redoes the item (same bytes).

Links: nothing is read or written through a symbolic link that leads out
of ``--out`` (a hostile folder could hold ``manifest.jsonl -> ~/.bashrc``).
Folders are resolved and must stay inside (:func:`inside`); the files
themselves are opened with ``O_NOFOLLOW`` (:func:`open_nofollow`) or
checked with ``lstat`` (:func:`regular_file`), and a write goes to a fresh
temporary name that is then renamed, which replaces a link instead of
following it.

Storage: the EXR writer reports a full disk as ``RuntimeError("... No
space left on device")``; :func:`write_item_files` turns such a message
into the ``OSError`` it stands for, naming the file, so that the run stops
on it (:mod:`.book`) instead of failing item after item.
"""

from __future__ import annotations

import errno
import hashlib
import os
import stat
import threading
from collections.abc import Callable, Iterable

TMP_MARK = ".tmp-"

Writer = Callable[[str], None]
"""Writes a file at the path it is given."""

STORAGE_MESSAGES = {
    "No space left on device": errno.ENOSPC,
    "Disk quota exceeded": errno.EDQUOT,
    "Read-only file system": errno.EROFS,
    "Permission denied": errno.EACCES,
    "Operation not permitted": errno.EPERM,
    "File too large": errno.EFBIG,
}
"""strerror texts (glibc's) that a writer may put in a message instead of
raising OSError, and their errno."""


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


def file_inside(root: str, rel: str) -> str:
    """The absolute path of the file ``rel`` under ``root``: its folders
    resolved and inside ``root`` (ValueError otherwise), its own name not
    followed (open it with :func:`open_nofollow`, or replace it)."""
    folder, name = os.path.split(rel)
    if not name or name in (".", "..") or os.path.isabs(rel) or "\x00" in rel:
        raise ValueError(f"path: {rel!r} must be a file's path relative to --out")
    return os.path.join(inside(root, folder) if folder else os.path.realpath(root), name)


def is_link_error(e: OSError) -> bool:
    """``O_NOFOLLOW`` met a link: ELOOP (Linux), EMLINK (FreeBSD), EFTYPE (NetBSD)."""
    return e.errno in (errno.ELOOP, errno.EMLINK, getattr(errno, "EFTYPE", -1))


def link_message(path: str) -> str:
    return (
        f"{path!r} is a symbolic link; the dataset command never reads or writes through links "
        "in --out (they could lead outside it): remove the link"
    )


def open_nofollow(path: str, flags: int, mode: int = 0o644) -> int:
    """``os.open`` of a regular file that refuses a link as the last
    component (``O_NOFOLLOW``): OSError(ELOOP) whose message says so, and
    anything but a regular file (``O_NONBLOCK``: opening a FIFO must not
    wait for a writer): OSError(EINVAL) saying what it is. The caller's
    folders are its own to check (:func:`inside`)."""
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, mode)
    except OSError as e:
        if is_link_error(e) and os.path.islink(path):
            raise OSError(errno.ELOOP, link_message(path), path) from e
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(errno.EINVAL, f"{path!r} is not a regular file", path)
    return fd


def write_new(path: str, data: bytes) -> None:
    """Writes ``data`` to a file that this call creates (``O_EXCL``, no link
    followed; a file or link already there is removed first: a temporary
    name of ours), and flushes it to disk."""
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
    fd = open_nofollow(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        os.fsync(fd)
    finally:
        os.close(fd)


def regular_file(path: str) -> bool:
    """Whether ``path`` is a regular file itself (``lstat``: a link is not)."""
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def sha256_file(path: str, *, follow: bool = True) -> str:
    """The file's sha256; ``follow=False`` refuses a link (OSError ELOOP)."""
    h = hashlib.sha256()
    fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC) if follow else open_nofollow(path, os.O_RDONLY)
    with open(fd, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _sync(fd: int) -> None:
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def final_name(path: str) -> str:
    """A temporary file's final name (the path itself otherwise): what an error message names."""
    head, mark, _ = path.rpartition(TMP_MARK)
    return head if mark else path


def as_storage_error(e: BaseException, path: str) -> OSError | None:
    """The storage error ``e`` stands for, naming the file (``path``, or the
    one ``e`` names): an OSError with a storage errno as it is, or a message
    holding a strerror of :data:`STORAGE_MESSAGES`; None for any other error."""
    if isinstance(e, OSError) and e.errno is not None and e.errno in STORAGE_MESSAGES.values():
        code, text = e.errno, e.strerror or os.strerror(e.errno)
        where = e.filename if isinstance(e.filename, str) else path
    else:
        found = next((m for m in STORAGE_MESSAGES if m.lower() in str(e).lower()), None)
        if found is None:
            return None
        code, text, where = STORAGE_MESSAGES[found], found, path
    return OSError(code, text, final_name(where))


def write_item_files(root: str, writers: dict[str, Writer]) -> dict[str, str]:
    """Writes every file (``rel path -> writer``) under ``root`` as described
    above; returns each file's sha256 by relative path."""
    finals = {rel: file_inside(root, rel) for rel in writers}
    tag = f"{TMP_MARK}{os.getpid()}-{threading.get_ident()}"
    temps: list[str] = []
    try:
        hashes = {}
        for rel, write in writers.items():
            final = finals[rel]
            try:
                os.makedirs(os.path.dirname(final), exist_ok=True)
                tmp = final + tag
                if os.path.lexists(tmp):  # never write through what is there (a link planted at our name)
                    os.unlink(tmp)
                temps.append(tmp)
                write(tmp)
                _sync(open_nofollow(tmp, os.O_RDONLY))
            except Exception as e:
                storage = as_storage_error(e, final)
                if storage is None:
                    raise
                raise storage from e
            hashes[rel] = sha256_file(tmp, follow=False)
        for rel in writers:
            os.replace(finals[rel] + tag, finals[rel])
        temps.clear()
        for folder in {os.path.dirname(p) for p in finals.values()}:
            _sync(os.open(folder, os.O_RDONLY))
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
        if os.path.islink(folder):  # a shard folder linked elsewhere is not ours to sweep
            continue
        try:
            names = os.listdir(folder)
        except (FileNotFoundError, NotADirectoryError):
            continue
        for name in names:
            if TMP_MARK in name:
                try:
                    os.unlink(os.path.join(folder, name))
                    removed += 1
                except FileNotFoundError:
                    pass
    return removed
