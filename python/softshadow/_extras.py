"""Importing an optional dependency, naming the extra that installs it.

``pip install softshadow`` installs numpy alone; the rest comes with the
extras of pyproject.toml (``io``: trimesh, OpenEXR, pillow; ``dataset``:
``io`` with tqdm, dask[distributed] and tomli; ``reference``: Mitsuba 3;
``plot``: matplotlib). A missing one raises :class:`MissingExtraError`,
a ``ModuleNotFoundError`` (so ``except ImportError`` still catches it)
whose message says what needed it and the one command that installs it,
instead of a bare ``No module named 'tqdm'`` from deep in a call.
"""

from __future__ import annotations

import importlib
from types import ModuleType


class MissingExtraError(ModuleNotFoundError):
    """An optional dependency is not installed; the message names its extra."""


def install_hint(extra: str) -> str:
    return f'pip install "softshadow[{extra}]"'


def require(module: str, extra: str, needed_for: str) -> ModuleType:
    """``module`` imported, or MissingExtraError: "``needed_for`` needs
    ``module``, part of the ``extra`` extra: pip install ...". Any failure
    to import counts (an ImportError inside the package, a module set to
    None in ``sys.modules``): the advice is the same, reinstalling it."""
    try:
        return importlib.import_module(module)
    except ImportError as e:
        top = module.partition(".")[0]
        raise MissingExtraError(
            f"{needed_for} needs {top}, part of softshadow's {extra!r} extra: {install_hint(extra)}", name=top
        ) from e
