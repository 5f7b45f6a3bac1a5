"""The package's exceptions. Values are refused with ValueError (its message
starting with the argument's name) and wrong types with TypeError; these two
add what those cannot say. Both are defined by the core (``_core``)."""

from __future__ import annotations

from ._core import GpuUnavailableError, TooLargeError

__all__ = ["GpuUnavailableError", "TooLargeError"]
