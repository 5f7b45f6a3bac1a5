"""Local worker processes die with the run that started them.

A ``ProcessPoolExecutor`` worker blocks on its task queue; when the main
process is SIGKILLed, nothing tells it, and it lived on (minutes later, 4
to 16 orphans, each holding a core's share of memory). Each worker, in its
initializer (:func:`die_with_parent`), asks two things:

* Linux's ``prctl(PR_SET_PDEATHSIG, SIGKILL)``: the kernel kills the worker
  when its parent exits. With forkserver the parent is the fork server,
  which exits as soon as the main process dies (its end of a pipe closes).
* A watchdog thread, for systems without prctl and for the moment before
  it was set: every :data:`POLL_SECONDS` it checks that its parent is the
  one it started with and that the main process is alive (a zombie is
  dead), and ends the process otherwise.

A killed worker leaves at most temporary files, which the next run sweeps.
Dask's LocalCluster workers need none of this: distributed ends them when
the process holding their nanny dies.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time

PR_SET_PDEATHSIG = 1
"""From <linux/prctl.h>."""
POLL_SECONDS = 0.5
"""The watchdog's period: a worker outlives the main process by at most this
(plus the time its current write takes to be interrupted: none, os._exit)."""


def parent_death_signal() -> bool:
    """Asks the kernel to SIGKILL this process when its parent exits; False
    where that cannot be had (not Linux, no prctl in the C library)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return int(libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)) == 0
    except (OSError, AttributeError):
        return False


def gone(pid: int) -> bool:
    """Whether process ``pid`` has died. A zombie has: whoever adopted it may
    never reap it (PID 1 in a container often does not)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rpartition(b")")[2].split()[0] in (b"Z", b"X")
    except FileNotFoundError:
        return True
    except (OSError, IndexError):
        pass  # no /proc: ask the kernel (a zombie then counts as alive until reaped)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False


def _watch(parent: int, main: int) -> None:
    while True:
        if os.getppid() != parent or gone(main):
            os._exit(1)  # no cleanup: the run is gone, and what this process wrote is swept by the next
        time.sleep(POLL_SECONDS)


def die_with_parent(*, prctl: bool = True) -> bool:
    """Makes this worker die with its parent and with the main process (see
    the module's docstring); returns whether the kernel will do it (prctl),
    the watchdog runs in any case."""
    parent = os.getppid()
    creator = multiprocessing.parent_process()  # the main process, with forkserver too
    main = creator.pid if creator is not None and creator.pid is not None else parent
    armed = prctl and parent_death_signal()
    threading.Thread(target=_watch, args=(parent, main), name="softshadow-lifeline", daemon=True).start()
    return armed
