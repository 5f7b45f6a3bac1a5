"""Soft-shadow datasets from a TOML spec: ``softshadow-dataset run`` and ``check``.

Item k of a dataset depends only on (spec, seed, k), so any subset
regenerates bit for bit on any number of workers; runs resume where they
stopped; ``check`` reports what is complete, missing or broken. The
modules, one job each: :mod:`.spec` (the spec, validated on load, with
:mod:`.fields` and :mod:`.limits`), :mod:`.sampling` (item k's random
parameters), :mod:`.build` (its scene, light and camera), :mod:`.item`
(render and write one item), :mod:`.files` (all-or-nothing writes inside
``--out``), :mod:`.manifest` (the output folder's bookkeeping),
:mod:`.runner` and :mod:`.dask_runner` (handing items out, with the
accounting they share in :mod:`.book`), :mod:`.check`, :mod:`.cli`. The format is in docs/dataset.md.
"""

from __future__ import annotations

from .check import CheckReport, check_output
from .fields import SpecError
from .manifest import OutputError, StorageError
from .runner import Summary, run
from .spec import Spec, load_spec, parse_spec

__all__ = [
    "CheckReport",
    "OutputError",
    "Spec",
    "SpecError",
    "StorageError",
    "Summary",
    "check_output",
    "load_spec",
    "parse_spec",
    "run",
]
