"""The client's accounting of a run, shared by the local runner
(:mod:`.runner`) and Dask's (:mod:`.dask_runner`): the :class:`Summary` a run
returns, the :class:`Book` that records each item's attempts in the manifest,
and the cores each local worker gets.

Two kinds of failure are not retried. A storage error (full disk, quota,
read-only or forbidden folder) stops the run: every further item would
fail the same way; it is recognised by its errno or, since OpenEXR reports
a full disk as ``RuntimeError("... No space left on device")``, by the
message. A :class:`.build.MeshError` (a mesh file the reader refuses) is
recorded at once: a broken input file is not a transient failure.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass, field
from typing import Any

from .build import MeshError
from .files import final_name
from .manifest import Output, StorageError

STORAGE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOTDIR, errno.EFBIG}

_STORAGE_TEXTS = {
    "No space left on device": errno.ENOSPC,
    "Disk quota exceeded": errno.EDQUOT,
    "Read-only file system": errno.EROFS,
}
"""Messages that mean the storage whatever raised them (a worker's writer
turns "Permission denied" into an OSError naming its file, :mod:`.files`;
here it could be an input's)."""

_ADVICE = {
    errno.ENOSPC: ("the disk is full", "Free space on it"),
    errno.EDQUOT: ("the disk quota is exceeded", "Free space or raise the quota"),
    errno.EROFS: ("the file system is read-only", "Make it writable or use another --out"),
    errno.EACCES: ("permission denied", "Make the folder writable by this user or use another --out"),
    errno.EPERM: ("operation not permitted", "Make the folder writable by this user or use another --out"),
    errno.ENOTDIR: ("a path on the way is a file", "Remove that file or use another --out"),
    errno.EFBIG: ("a file is too large for the file system", "Use another --out"),
}


@dataclass
class Summary:
    done: int = 0
    """Items made by this run."""
    skipped: int = 0
    """Items already complete."""
    failed: dict[int, str] = field(default_factory=dict)
    """Items that failed every attempt, with their last error."""
    retried: int = 0
    seconds: float = 0.0
    workers: str = ""

    @property
    def items_per_second(self) -> float:
        return self.done / self.seconds if self.seconds > 0 else 0.0

    def __str__(self) -> str:
        s = (
            f"{self.done} items made, {self.skipped} skipped (already complete), {len(self.failed)} failed, "
            f"{self.retried} retries; {self.seconds:.1f} s, {self.items_per_second:.2f} items/s ({self.workers})"
        )
        for k, err in list(self.failed.items())[:20]:
            s += f"\n  item {k} failed: {err}"
        return s


def _error_text(e: BaseException) -> str:
    return f"{type(e).__name__}: {e}"


def storage_error(e: BaseException) -> OSError | None:
    """The storage error ``e`` is or stands for (see the module's docstring), or None."""
    if isinstance(e, OSError):
        return e if e.errno in STORAGE_ERRNOS else None
    text = str(e).lower()
    for message, code in _STORAGE_TEXTS.items():
        if message.lower() in text:
            return OSError(code, message)
    return None


def storage_problem(e: BaseException) -> bool:
    return storage_error(e) is not None


def storage_message(e: OSError, root: str, done: int) -> str:
    """What happened, where, and what to do: the text of the StorageError that stops a run."""
    what, advice = _ADVICE.get(e.errno or 0, ("the folder cannot take files", "Fix the folder"))
    where = final_name(e.filename) if isinstance(e.filename, str) else root
    code = errno.errorcode.get(e.errno or 0, "?")
    return (
        f"out: {what}: cannot write {where!r}: {e.strerror or e} ({code}). {advice}, then rerun the same "
        f"command to resume: {done} items made by this run are complete and are kept (nothing half-written is)"
    )


class Book:
    """The client's accounting: manifest lines, attempts, progress."""

    def __init__(self, output: Output, retries: int, bar: Any, summary: Summary) -> None:
        self.output, self.retries, self.bar, self.summary = output, retries, bar, summary
        self.attempts: dict[int, int] = {}
        self.finished: set[int] = set()

    def done(self, k: int, result: dict[str, Any]) -> None:
        if k in self.finished:  # a duplicate result (a task run twice): already counted
            return
        self.finished.add(k)
        self.output.append({**result, "status": "done", "attempts": self.attempts.get(k, 0) + 1})
        self.summary.done += 1
        self.bar.update(1)

    def failed_attempt(self, k: int, e: BaseException) -> bool:
        """Records a failed attempt; True if item k should be tried again."""
        storage = storage_error(e)
        if storage is not None:
            raise StorageError(storage_message(storage, self.output.root, self.summary.done)) from e
        n = self.attempts[k] = self.attempts.get(k, 0) + 1
        if n <= self.retries and not isinstance(e, MeshError):
            self.summary.retried += 1
            return True
        self.finished.add(k)
        self.summary.failed[k] = _error_text(e)
        self.output.append({"k": k, "status": "failed", "error": _error_text(e), "attempts": n})
        self.bar.update(1)
        self.bar.set_postfix(failed=len(self.summary.failed))
        return False


def default_threads(workers: int) -> int:
    """The cores shared among the workers (at least 1 each)."""
    return max(1, (os.cpu_count() or 1) // workers)
