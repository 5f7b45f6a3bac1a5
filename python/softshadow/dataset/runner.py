"""``softshadow-dataset run``: make the items of a spec that ``--out`` lacks.

The client (this process) opens the output folder (:class:`.manifest.Output`),
lists the items still to make (the manifest's done items whose files exist
are skipped; ``verify`` also re-hashes them), and hands them out with a
bounded window of tasks in flight: to itself (one worker), to local
processes (``ProcessPoolExecutor``, forkserver), or to Dask. Workers render
and write their item's files (:func:`.item.make_item`); the client appends
each result to the manifest, retries a failed item up to ``retries`` times
on any worker, then records it as failed and goes on (the accounting,
:class:`.book.Book`, is shared with :mod:`.dask_runner`). A worker process that
dies costs only the items it held: they are handed out again (the local
pool is rebuilt; Dask's scheduler reschedules by itself). Errors of the
output's storage (full disk, read-only or forbidden folder) stop the run:
every further item would fail the same way. Local worker processes die
with the run (:mod:`.lifeline`), however it dies.

Before any work: every argument is checked against its range
(:mod:`.limits`), and the optional packages the run will use are imported
(a missing one is named with its extra, :mod:`softshadow._extras`).
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections import deque
from collections.abc import Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from .._extras import require
from . import limits as L
from .book import STORAGE_ERRNOS as STORAGE_ERRNOS  # re-exported, as before the move
from .book import Book, Summary, default_threads
from .book import storage_problem as storage_problem
from .check import check_item
from .dask_runner import run_dask
from .files import regular_file, sweep_temporaries
from .item import item_files, make_item
from .lifeline import die_with_parent
from .manifest import Output, read_dataset, read_manifest
from .progress import progress_bar
from .spec import Spec


def parse_items(text: str, count: int) -> list[int]:
    """``"0-9,15"`` -> the sorted items, each below ``count``; ValueError naming ``items``."""
    ks: set[int] = set()
    for part in text.split(","):
        lo_s, _, hi_s = part.strip().partition("-")
        try:
            lo = int(lo_s)
            hi = int(hi_s) if hi_s else lo
        except ValueError as e:
            raise ValueError(f"items: {part!r} is not an item number or a range like 3-7") from e
        if not 0 <= lo <= hi < count:
            raise ValueError(f"items: {part!r} must lie within 0..{count - 1}")
        if hi - lo >= L.MAX_COUNT:
            raise ValueError(f"items: {part!r} is too long a range")
        ks.update(range(lo, hi + 1))
    return sorted(ks)


def _item_folders(output: Output) -> list[str]:
    folder = os.path.join(output.root, output.spec.outputs.folder)
    try:
        return [os.path.join(folder, d) for d in os.listdir(folder)]
    except (FileNotFoundError, NotADirectoryError):
        return []


def complete_items(out: str, spec: Spec, *, verify: bool) -> set[int]:
    """Items the manifest lists as done whose files are all there (and, with ``verify``, sound)."""
    info = read_dataset(out)
    done = set()
    for k, rec in read_manifest(out).items():
        if rec.get("status") != "done":
            continue
        if verify:
            if check_item(out, info, k, rec) is None:
                done.add(k)
        elif set(rec.get("files", {})) == set(item_files(spec, k).values()) and all(
            regular_file(os.path.join(out, rel))
            for rel in rec["files"]  # a link is not an item's file
        ):
            done.add(k)
    return done


def _check_arguments(**values: int | None) -> None:
    """ValueError naming the first argument out of its range (None: the default)."""
    bounds = {
        "count": (1, L.MAX_COUNT),
        "workers": (1, L.MAX_WORKERS),
        "retries": (0, L.MAX_RETRIES),
        "threads": (1, L.MAX_THREADS),
        "window": (1, L.MAX_WINDOW),
    }
    for name, value in values.items():
        lo, hi = bounds[name]
        if value is None and name in ("threads", "window"):
            continue
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ValueError(f"{name}: must be an integer in [{lo}, {hi}], got {value!r}")


def run(
    spec: Spec,
    out: str | os.PathLike[str],
    *,
    count: int | None = None,
    items: Iterable[int] | None = None,
    workers: int = 1,
    threads: int | None = None,
    dask: Any = None,
    retries: int = 2,
    window: int | None = None,
    verify: bool = False,
    progress: bool = True,
) -> Summary:
    """Makes the missing items of ``spec`` in ``out``; returns the summary.

    ``dask``: None (local), ``"local"`` (a LocalCluster of ``workers``
    processes), a scheduler address, or a ``distributed.Client``.
    ``threads``: the core's threads per item (default: the cores divided
    among the local workers; 1 per Dask task on a cluster you give).
    Raises StorageError when the folder cannot take files, OutputError or
    SpecError when it cannot be used at all, ValueError naming an argument
    out of its range, MissingExtraError naming the extra of a missing
    optional package (tqdm only with ``progress``), all before any work.
    """
    count = spec.count if count is None else count
    _check_arguments(count=count, workers=workers, retries=retries, threads=threads, window=window)
    wanted = list(range(count)) if items is None else sorted(set(items))
    if wanted and not 0 <= wanted[0] <= wanted[-1] < count:
        raise ValueError(f"items: must lie within 0..{count - 1}")
    require("OpenEXR", "dataset", "writing the items' EXR files")
    if dask is not None:
        require("distributed", "dataset", "handing items to Dask (dask=, --dask)")
    new_bar = progress_bar(shown=progress)

    with Output(os.fspath(out), spec, count) as output:
        sweep_temporaries(_item_folders(output))  # the lock is ours: no writer is running
        # Without dataset.json (deleted after damage) the manifest's items may be another spec's: re-check them.
        done = complete_items(output.root, spec, verify=verify or output.recovered)
        todo = [k for k in wanted if k not in done]
        summary = Summary(skipped=len(wanted) - len(todo))
        t0 = time.perf_counter()
        with new_bar(len(todo)) as bar:
            book = Book(output, retries, bar, summary)
            try:
                if dask is not None:
                    summary.workers = run_dask(book, spec, output.root, todo, dask, workers, threads, window)
                elif workers == 1:
                    summary.workers = _run_serial(book, spec, output.root, todo, threads)
                else:
                    summary.workers = _run_pool(book, spec, output.root, todo, workers, threads, window)
            finally:
                summary.seconds = time.perf_counter() - t0
        sweep_temporaries(_item_folders(output))
    return summary


def _run_serial(book: Book, spec: Spec, out: str, todo: list[int], threads: int | None) -> str:
    for k in todo:
        while True:
            try:
                book.done(k, make_item(spec, out, k, threads))
            except Exception as e:
                if book.failed_attempt(k, e):
                    continue
            break
    return "1 local worker"


def _init_worker(threads: int) -> None:
    os.environ["SOFTSHADOW_THREADS"] = str(threads)
    die_with_parent()  # no orphan left working when the run is killed


def _run_pool(
    book: Book, spec: Spec, out: str, todo: list[int], workers: int, threads: int | None, window: int | None
) -> str:
    threads = threads or default_threads(workers)
    window = window or 2 * workers
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    context = multiprocessing.get_context(method)
    pending = deque(todo)
    inflight: dict[Future[dict[str, Any]], int] = {}

    def new_pool() -> ProcessPoolExecutor:
        return ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker, initargs=(threads,))

    pool = new_pool()
    try:
        while pending or inflight:
            while pending and len(inflight) < window:
                k = pending.popleft()
                inflight[pool.submit(make_item, spec, out, k, threads)] = k
            finished, _ = wait(inflight, return_when=FIRST_COMPLETED)
            broken = False
            for fut in finished:
                k = inflight.pop(fut)
                try:
                    result = fut.result()
                except BrokenProcessPool as e:
                    broken = True
                    if book.failed_attempt(k, RuntimeError(f"a worker process died ({e})")):
                        pending.appendleft(k)
                except Exception as e:
                    if book.failed_attempt(k, e):
                        pending.appendleft(k)
                else:
                    book.done(k, result)
            if broken:  # every task still held by the dead pool is lost: hand them out again
                pool.shutdown(wait=True, cancel_futures=True)
                for fut, k in list(inflight.items()):
                    if fut.done() and not fut.cancelled() and fut.exception() is None:
                        book.done(k, fut.result())
                    else:
                        pending.appendleft(k)
                inflight.clear()
                pool = new_pool()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return f"{workers} local processes x {threads} threads"
