"""The package's exceptions. Values are refused with ValueError (its message
starting with the argument's name) and wrong types with TypeError; these two
add what those cannot say."""

from __future__ import annotations

from ._core import GpuUnavailableError


class TooLargeError(ValueError, MemoryError):
    """A request refused before allocating because it would need too much
    memory. Both a ValueError (a bad argument) and a MemoryError."""


__all__ = ["GpuUnavailableError", "TooLargeError"]
