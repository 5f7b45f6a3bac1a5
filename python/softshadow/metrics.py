"""Error metrics between a computed visibility map and a reference one.

Pure NumPy. Visibility maps hold, per texel, the fraction of the light seen
from the receiver point (1 = lit, 0 = umbra); occlusion is ``1 - visibility``.

The main metric is the one of Atty et al. 2005, "Soft Shadow Maps", §4.2.1:
the sum of ``|V - V_ref|`` divided by the number of texels that are in the
reference shadow (umbra or penumbra), i.e. the mean absolute error over the
actual soft shadow. Dividing by all texels would under-estimate the error when
the shadow covers a small part of the map.

Every function rejects NaN and inf with a ``ValueError``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["compare", "max_error", "rmse", "shadow_error", "shadow_mask"]

#: Default occlusion above which a reference texel counts as in shadow.
DEFAULT_THRESHOLD = 1e-3


def _finite_array(values: Any, name: str) -> np.ndarray:
    """Convert to a float64 array, raising ``ValueError`` on NaN or inf."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of numbers") from exc
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or inf values")
    return array


def _pair(v: Any, v_ref: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate two maps: finite and of equal shape."""
    a = _finite_array(v, "v")
    b = _finite_array(v_ref, "v_ref")
    if a.shape != b.shape:
        raise ValueError(f"v has shape {a.shape} but v_ref has shape {b.shape}")
    return a, b


def _mask(mask: Any, shape: tuple[int, ...]) -> np.ndarray:
    """Validate an optional boolean mask of the maps' shape (None = all)."""
    if mask is None:
        return np.ones(shape, dtype=bool)
    array = np.asarray(mask)
    if array.dtype != np.bool_:
        raise TypeError(f"mask must be boolean, got dtype {array.dtype}")
    if array.shape != shape:
        raise ValueError(f"mask has shape {array.shape} but the maps have {shape}")
    return array


def _threshold(threshold: Any) -> float:
    """Validate the occlusion threshold: a finite number in [0, 1)."""
    value = float(threshold)
    if not (np.isfinite(value) and 0.0 <= value < 1.0):
        raise ValueError(f"threshold must be in [0, 1), got {threshold}")
    return value


def shadow_mask(v_ref: Any, *, threshold: float = DEFAULT_THRESHOLD) -> np.ndarray:
    """Texels in the reference umbra or penumbra.

    Parameters
    ----------
    v_ref : array_like
        Reference visibility.
    threshold : float, optional
        A texel is in shadow when its occlusion ``1 - v_ref`` exceeds this
        (strictly), which ignores sampling noise in fully lit regions.

    Returns
    -------
    numpy.ndarray of bool
        Same shape as ``v_ref``.
    """
    reference = _finite_array(v_ref, "v_ref")
    return (1.0 - reference) > _threshold(threshold)


def shadow_error(v: Any, v_ref: Any, *, threshold: float = DEFAULT_THRESHOLD) -> float:
    """Mean absolute visibility error over the reference soft shadow.

    The error metric of Atty et al. 2005, §4.2.1: ``sum |v - v_ref|`` over
    the texels where the reference occlusion ``1 - v_ref`` exceeds
    ``threshold`` (umbra and penumbra), divided by their number. Errors in
    texels outside the reference shadow (e.g. spurious shadows on lit
    receivers) are not counted, as in the paper; use :func:`rmse` or
    :func:`max_error` for those.

    Parameters
    ----------
    v : array_like
        Computed visibility.
    v_ref : array_like
        Reference visibility, same shape.
    threshold : float, optional
        Occlusion threshold of :func:`shadow_mask`.

    Returns
    -------
    float
        The error; ``0.0`` when the reference has no shadowed texel (there is
        no soft shadow to be wrong about).

    Raises
    ------
    ValueError
        On shape mismatch, NaN or inf, or a threshold outside [0, 1).
    """
    a, b = _pair(v, v_ref)
    in_shadow = (1.0 - b) > _threshold(threshold)
    count = int(np.count_nonzero(in_shadow))
    if count == 0:
        return 0.0
    return float(np.abs(a[in_shadow] - b[in_shadow]).sum() / count)


def rmse(v: Any, v_ref: Any, *, mask: Any = None) -> float:
    """Root-mean-square difference over all texels (or those in ``mask``).

    Parameters
    ----------
    v, v_ref : array_like
        Computed and reference visibility, same shape.
    mask : array_like of bool, optional
        Texels to include; all by default.

    Returns
    -------
    float
        The RMSE; ``0.0`` when no texel is selected.
    """
    a, b = _pair(v, v_ref)
    selected = _mask(mask, a.shape)
    if not selected.any():
        return 0.0
    return float(np.sqrt(np.mean((a[selected] - b[selected]) ** 2)))


def max_error(v: Any, v_ref: Any, *, mask: Any = None) -> float:
    """Largest absolute difference over all texels (or those in ``mask``).

    Parameters
    ----------
    v, v_ref : array_like
        Computed and reference visibility, same shape.
    mask : array_like of bool, optional
        Texels to include; all by default.

    Returns
    -------
    float
        The maximum error; ``0.0`` when no texel is selected.
    """
    a, b = _pair(v, v_ref)
    selected = _mask(mask, a.shape)
    if not selected.any():
        return 0.0
    return float(np.max(np.abs(a[selected] - b[selected])))


def compare(v: Any, v_ref: Any, *, threshold: float = DEFAULT_THRESHOLD) -> dict[str, float | int]:
    """All metrics at once.

    Parameters
    ----------
    v, v_ref : array_like
        Computed and reference visibility, same shape.
    threshold : float, optional
        Occlusion threshold defining the reference shadow.

    Returns
    -------
    dict
        ``error`` (:func:`shadow_error`), ``rmse`` and ``max`` (over all
        texels) as floats, and ``shadow_texels``, the number of texels in the
        reference shadow, as an int.
    """
    a, b = _pair(v, v_ref)
    return {
        "error": shadow_error(a, b, threshold=threshold),
        "rmse": rmse(a, b),
        "max": max_error(a, b),
        "shadow_texels": int(np.count_nonzero(shadow_mask(b, threshold=threshold))),
    }
