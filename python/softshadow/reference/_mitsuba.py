"""Mitsuba 3 set-up: the LLVM library for Dr.Jit, the variant, scene objects.

Dr.Jit's LLVM backend needs libLLVM >= 16 (older versions crash it) and by
default may load an older system one, so this module points
``DRJIT_LIBLLVM_PATH`` at the newest libLLVM >= 16 it finds in Debian's and
Ubuntu's install locations. That happens when this module is imported (so
``import softshadow.reference`` before ``import mitsuba`` suffices) and again
before Mitsuba is imported here; a value the user set is never changed, and
nothing is changed once Dr.Jit is loaded. This is the only place in the
project that looks for the library.

Mitsuba's variant is process-global. The first call of :func:`_mitsuba`
picks ``llvm_ad_rgb`` when Dr.Jit can load libLLVM >= 16 and ``scalar_rgb``
otherwise, and selects it once; see :func:`variant`.

Mitsuba itself is imported lazily, on the first call that needs it.
"""

from __future__ import annotations

import glob
import os
import re
import sys
from typing import Any

import numpy as np

from ._inputs import _light_frame

_INSTALL_HINT = "pip install softshadow[reference]"
#: Environment variable forcing the variant ("llvm_ad_rgb" or "scalar_rgb").
VARIANT_ENV = "SOFTSHADOW_MITSUBA_VARIANT"
#: Environment variable Dr.Jit reads for the path of libLLVM.
LLVM_PATH_ENV = "DRJIT_LIBLLVM_PATH"
_SUPPORTED_VARIANTS = ("llvm_ad_rgb", "scalar_rgb")
_MIN_LLVM_MAJOR = 16
# Where Debian/Ubuntu install versioned LLVM libraries; the newest one wins.
_LLVM_GLOBS = (
    "/usr/lib/x86_64-linux-gnu/libLLVM-[0-9][0-9].so",
    "/usr/lib/aarch64-linux-gnu/libLLVM-[0-9][0-9].so",
    "/usr/lib/llvm-[0-9][0-9]/lib/libLLVM.so",
)
_LLVM_VERSION = re.compile(r"libLLVM-(\d+)\.so$|llvm-(\d+)/lib/libLLVM\.so$")

_variant: str | None = None


# --------------------------------------------------------------------------
# Mitsuba loading and variant selection
# --------------------------------------------------------------------------


def _newest_llvm_library() -> str | None:
    """Return the path of the newest libLLVM >= 16 found on this system."""
    best: tuple[int, str] | None = None
    for pattern in _LLVM_GLOBS:
        for path in glob.glob(pattern):
            match = _LLVM_VERSION.search(path)
            if match is None:
                continue
            major = int(match.group(1) or match.group(2))
            if major >= _MIN_LLVM_MAJOR and (best is None or major > best[0]):
                best = (major, path)
    return None if best is None else best[1]


def _use_newest_llvm() -> None:
    """Set ``DRJIT_LIBLLVM_PATH`` to the newest libLLVM >= 16, if that is safe.

    Dr.Jit reads the variable when it initialises its LLVM backend, so it is
    set only while Dr.Jit is not loaded yet, and never over a user's value.
    """
    if LLVM_PATH_ENV not in os.environ and "drjit" not in sys.modules:
        library = _newest_llvm_library()
        if library is not None:
            os.environ[LLVM_PATH_ENV] = library


def _import_mitsuba() -> tuple[Any, Any]:
    """Import ``mitsuba`` and ``drjit`` with a usable LLVM library."""
    _use_newest_llvm()
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        raise ImportError(
            f"softshadow.reference needs Mitsuba 3 and Dr.Jit; install them with `{_INSTALL_HINT}`"
        ) from exc
    return mi, dr


def _llvm_usable(mi: Any, dr: Any) -> bool:
    """Whether the ``llvm_ad_rgb`` variant exists and runs on a safe LLVM."""
    if "llvm_ad_rgb" not in mi.variants():
        return False
    if not dr.has_backend(dr.JitBackend.LLVM):  # also initialises the backend
        return False
    version = getattr(dr.detail, "llvm_version", None)
    if version is None:  # older Dr.Jit without the query: trust the backend
        return True
    return tuple(version())[0] >= _MIN_LLVM_MAJOR


def _choose_variant(mi: Any, dr: Any) -> str:
    """Pick the variant: forced by env, else the active one, else the best."""
    forced = os.environ.get(VARIANT_ENV)
    if forced:
        if forced not in _SUPPORTED_VARIANTS:
            raise ValueError(f"{VARIANT_ENV}={forced!r}: expected one of {_SUPPORTED_VARIANTS}")
        if forced == "llvm_ad_rgb" and not _llvm_usable(mi, dr):
            raise RuntimeError(
                f"{VARIANT_ENV}=llvm_ad_rgb but Dr.Jit cannot use libLLVM >= {_MIN_LLVM_MAJOR}; set {LLVM_PATH_ENV}"
            )
        return forced
    # Respect a supported variant the user already selected in this process.
    if mi.variant() in _SUPPORTED_VARIANTS:
        return mi.variant()
    return "llvm_ad_rgb" if _llvm_usable(mi, dr) else "scalar_rgb"


def _mitsuba() -> tuple[Any, Any]:
    """Return ``(mi, dr)`` with this module's variant active.

    The variant is chosen on the first call and then kept; it is re-activated
    only if other code switched Mitsuba to another variant in between, because
    ``mi.*`` types resolve against the active variant at call time.
    """
    global _variant
    mi, dr = _import_mitsuba()
    if _variant is None:
        _variant = _choose_variant(mi, dr)
    if mi.variant() != _variant:
        mi.set_variant(_variant)
    return mi, dr


def variant() -> str:
    """Return the Mitsuba variant used by this module, selecting it if needed.

    Returns
    -------
    str
        ``"llvm_ad_rgb"`` when Dr.Jit can load libLLVM >= 16, else
        ``"scalar_rgb"``. The environment variable
        ``SOFTSHADOW_MITSUBA_VARIANT`` forces either one; a supported variant
        already active in the process is kept.
    """
    _mitsuba()
    assert _variant is not None
    return _variant


# --------------------------------------------------------------------------
# Mitsuba scene construction
# --------------------------------------------------------------------------


def _mitsuba_mesh(mi: Any, name: str, vertices: np.ndarray, faces: np.ndarray, bsdf: Any = None) -> Any:
    """Build a ``mi.Mesh`` from float32 vertices and uint32 faces (no files)."""
    props = mi.Properties()
    if bsdf is not None:
        props["bsdf"] = bsdf
    mesh = mi.Mesh(name, len(vertices), len(faces), props)
    params = mi.traverse(mesh)
    # Use the buffer types Mitsuba exposes, so this works for every variant
    # (drjit.llvm.ad.Float in llvm_*, drjit.scalar.ArrayXf in scalar_*).
    params["vertex_positions"] = type(params["vertex_positions"])(vertices.ravel())
    params["faces"] = type(params["faces"])(faces.ravel())
    params.update()
    return mesh


def _light_to_world(mi: Any, light: Any) -> Any:
    """``to_world`` of a Mitsuba ``rectangle`` matching a softshadow light.

    The rectangle spans [-1, 1]^2 in its local xy plane and emits toward its
    local +z. (u, v, n) is left-handed, so mapping x->u, y->v, z->n would be a
    mirroring transform (negative determinant), leaving the emitting side to
    Mitsuba's handling of reflections. Instead x -> v*sy/2, y -> u*sx/2,
    z -> n is right-handed (v x u = n) and covers the same rectangle.
    """
    c, u, v, n, sx, sy = _light_frame(light)
    matrix = np.eye(4)
    matrix[:3, 0] = v * (sy / 2.0)
    matrix[:3, 1] = u * (sx / 2.0)
    matrix[:3, 2] = n
    matrix[:3, 3] = c
    return mi.ScalarTransform4f(matrix)


# Done on import, so that importing softshadow.reference before mitsuba is
# enough for Dr.Jit to find a usable LLVM (tests/conftest.py relies on it).
_use_newest_llvm()
