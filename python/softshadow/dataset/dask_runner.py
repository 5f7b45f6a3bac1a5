"""Handing items to Dask: a LocalCluster (``"local"``), a scheduler's address, or a given Client.

A bounded window of tasks is in flight (``as_completed(...).add``):
submitting millions of tasks at once stalls the scheduler and the client.
Workers write their items' files (the output folder must be shared with
them); the client gets back only the small manifest entry, writes the
manifest and drives the progress bar. A worker that dies is Dask's to
handle: its tasks are rescheduled on the others (up to the scheduler's
``allowed-failures``, then ``KilledWorker`` comes back as the task's error
and the client's own retries apply). Each attempt has its own key, so a
retry is never mistaken for the failed task.
"""

from __future__ import annotations

import uuid
from collections import deque
from typing import Any

from .._extras import require
from .book import Book, default_threads
from .item import make_item
from .spec import Spec


def run_dask(
    book: Book, spec: Spec, out: str, todo: list[int], dask: Any, workers: int, threads: int | None, window: int | None
) -> str:
    distributed = require("distributed", "dataset", "handing items to Dask (dask=, --dask)")
    Client, LocalCluster, as_completed = distributed.Client, distributed.LocalCluster, distributed.as_completed

    own: list[Any] = []
    if isinstance(dask, Client):
        client = dask
        where = f"Dask client {client.scheduler.address if client.scheduler else ''}"
        threads = threads or 1
    elif dask == "local":
        threads = threads or default_threads(workers)
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0")
        client = Client(cluster)
        own += [client, cluster]
        where = f"Dask LocalCluster of {workers} processes x {threads} threads"
    elif isinstance(dask, str):
        try:
            client = Client(dask)
        except OSError as e:  # distributed's connection errors (timeouts included)
            raise ValueError(f"dask: cannot connect to the scheduler {dask!r}: {e}") from e
        own.append(client)
        threads = threads or 1
        where = f"Dask scheduler {dask}"
    else:
        raise TypeError(
            f"dask: must be 'local', a scheduler address or a distributed.Client, got {type(dask).__name__}"
        )
    try:
        slots = sum(client.nthreads().values()) or 1
        window = window or max(4, 2 * slots)
        spec_future = client.scatter(spec, broadcast=True)
        run_id = uuid.uuid4().hex[:8]
        pending = deque(todo)
        keys: dict[str, int] = {}
        attempt: dict[int, int] = {}

        def submit(k: int) -> Any:
            attempt[k] = attempt.get(k, 0) + 1
            key = f"softshadow-item-{run_id}-{k}-{attempt[k]}"
            keys[key] = k
            return client.submit(make_item, spec_future, out, k, threads, key=key, pure=False)

        first = [submit(pending.popleft()) for _ in range(min(window, len(pending)))]
        flight = as_completed(first)
        for fut in flight:
            k = keys.pop(fut.key)
            if fut.status == "finished":
                book.done(k, fut.result())
            else:
                error = fut.exception()
                if book.failed_attempt(k, error):
                    flight.add(submit(k))
            fut.release()
            if pending:
                flight.add(submit(pending.popleft()))
        return where
    finally:
        for thing in own:
            thing.close()
