"""The progress bar of a run: tqdm's on stderr, or none.

tqdm is an optional dependency (the ``dataset`` extra); a run without a bar
(``--quiet``, ``progress=False``) must not need it, so it gets
:class:`NoBar`, which takes the same calls and does nothing.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

from .._extras import require


class NoBar:
    """The calls :class:`.book.Book` makes on a bar, doing nothing."""

    def update(self, n: int = 1) -> None:
        pass

    def set_postfix(self, **values: Any) -> None:
        pass

    def __enter__(self) -> NoBar:
        return self

    def __exit__(self, *exc: object) -> None:
        pass


def progress_bar(*, shown: bool) -> Callable[[int], Any]:
    """Makes bars over ``total`` items: tqdm's, or :class:`NoBar`. Called
    before any work, so that a missing tqdm stops the run up front
    (MissingExtraError naming the extra and ``--quiet``)."""
    if not shown:
        return lambda total: NoBar()
    tqdm = require("tqdm", "dataset", "the progress bar (--quiet, or progress=False, runs without it)")
    return lambda total: tqdm.tqdm(total=total, unit="item", desc="items", file=sys.stderr)
