"""The limits a dataset spec and a run must respect, in one place.

A spec that exceeds one is refused on load, before any work, with the field
named; a command-line argument out of its range is refused by the parser
(exit code 2) naming the argument, and :func:`.runner.run` refuses the same
values (docs/dataset.md lists them). They bound what a hostile or mistyped
spec or command can make the machine do: allocate absurd images, loop for
ever, or write outside ``--out``.
"""

from __future__ import annotations

MAX_COUNT = 100_000_000
"""Items per dataset (``count``, ``--count``); item names have 8 digits."""
MAX_SIDE = 8192
"""Pixels per side of the eye view and of the light-view maps."""
MAX_SEED = 2**63 - 1
"""The largest ``seed``."""
MAX_VIEWS = 1024
"""Items per scene (``views``)."""
MAX_OBJECT_ENTRIES = 64
"""``[[objects]]`` tables per spec."""
MAX_INSTANCES = 1000
"""Instances one ``[[objects]]`` table may place per item (``count``, ``grid``)."""
MAX_LIGHT_ENTRIES = 16
"""``[[lights]]`` tables per spec."""
MAX_LIGHTS_PER_ITEM = 32
"""Lights one item draws (``lights_per_item``); the core's own bound on one
call's lights (``softshadow.limits()["lights"]``) applies too."""
MAX_MESH_FILES = 100_000
"""Mesh files one folder may hold."""
MAX_COORDINATE = 1.0e6
"""Largest absolute world coordinate, distance, size or scale."""
MAX_RETRIES = 100
"""``--retries``."""
MAX_WORKERS = 1024
"""``--workers``."""
MAX_THREADS = 1024
"""``--threads``: the core's own bound on ``threads=`` (``softshadow.limits()["max_threads"]``)."""
MAX_WINDOW = 100_000
"""``--window``: tasks in flight at once. More only loads the scheduler (the
default is 2 per worker thread, so this serves 50 000 threads)."""
MAX_NAME = 64
"""Characters of ``outputs.folder``."""

ITEM_DIGITS = 8
"""Digits of an item's file name (``00000042``)."""
SHARD = 1000
"""Items per subfolder of ``outputs.folder`` (``00000`` holds items 0-999)."""
