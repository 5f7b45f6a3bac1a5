"""The client's accounting of a run, shared by the local runner
(:mod:`.runner`) and Dask's (:mod:`.dask_runner`): the :class:`Summary` a run
returns, the :class:`Book` that records each item's attempts in the manifest,
and the cores each local worker gets.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass, field
from typing import Any

from .manifest import Output, StorageError

STORAGE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOTDIR, errno.EFBIG}


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


def storage_problem(e: BaseException) -> bool:
    return isinstance(e, OSError) and e.errno in STORAGE_ERRNOS


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
        if storage_problem(e):
            assert isinstance(e, OSError)
            where = f" writing {e.filename!r}" if e.filename else ""
            raise StorageError(
                f"out: cannot write{where}: {e.strerror or e} ({errno.errorcode.get(e.errno or 0, '?')}); "
                f"{self.summary.done} items made by this run are complete; fix the folder and rerun to resume"
            ) from e
        n = self.attempts[k] = self.attempts.get(k, 0) + 1
        if n <= self.retries:
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
