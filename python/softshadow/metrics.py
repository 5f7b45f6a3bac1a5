"""Error metrics between a computed visibility map and a reference one.

Pure NumPy. Visibility maps hold, per texel, the fraction of the light seen
from the receiver point (1 = lit, 0 = umbra); occlusion is ``1 - visibility``.

The main metric is the one of Atty et al. 2005, "Soft Shadow Maps", §4.2.1:
the sum of ``|V - V_ref|`` divided by the number of texels that are in the
reference shadow (umbra or penumbra), i.e. the mean absolute error over the
actual soft shadow. Dividing by all texels would under-estimate the error when
the shadow covers a small part of the map.

The map functions reject NaN and inf with a ``ValueError``.

Eye-view images (:func:`compare_images`) are compared only where both see
the same surface point: both hit (``mask``), the same mesh (``mesh_id``),
at positions within ``position_tol`` times the reference's depth of each
other. The headline is the same metric as the light view's, over the
*matched* pixels the reference shadows (``shadow_error``); the mean over
every matched pixel (``mean_abs``), lit ones included, is kept beside it but
hides shadow errors behind lit pixels and is not comparable between scenes.

Two failure rates go with every comparison, in both views (:func:`acne_leak`):
*acne*, the pixels (texels) the reference sees fully lit (``V_ref >= 0.99``)
that the method darkens by more than 0.05, and *leaks*, the pixels in the
reference umbra (``V_ref <= 0.01``) that the method lightens by more than
0.05; each as a fraction of the pixels compared.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "ImageComparison",
    "acne_leak",
    "compare",
    "compare_images",
    "max_error",
    "rmse",
    "shadow_error",
    "shadow_mask",
]

#: Default occlusion above which a reference texel counts as in shadow.
DEFAULT_THRESHOLD = 1e-3
#: A reference visibility at least this is fully lit (for the acne rate).
LIT = 0.99
#: A reference visibility at most this is umbra (for the leak rate).
UMBRA = 0.01
#: How far a method must darken a lit pixel (lighten an umbra one) to count
#: as acne (a leak).
ACNE_LEAK_MARGIN = 0.05


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


def acne_leak(v: Any, v_ref: Any, *, mask: Any = None) -> tuple[float, float]:
    """Acne and leak rates over all texels (or those in ``mask``).

    *Acne*: the reference sees the texel fully lit (``v_ref >= 0.99``) and
    ``v`` is darker by more than 0.05 (a surface shadowing itself, a false
    shadow). *Leak*: the reference has it in umbra (``v_ref <= 0.01``) and
    ``v`` is lighter by more than 0.05 (light through a closed mesh, a
    lost occluder). Each count is divided by the texels selected, so the two
    rates and the shadow error describe the same set.

    Returns
    -------
    (float, float)
        ``(acne, leak)``, each in [0, 1]; ``(0.0, 0.0)`` when no texel is
        selected.
    """
    a, b = _pair(v, v_ref)
    selected = _mask(mask, a.shape)
    n = int(np.count_nonzero(selected))
    if n == 0:
        return 0.0, 0.0
    acne = selected & (b >= LIT) & (a < b - ACNE_LEAK_MARGIN)
    leak = selected & (b <= UMBRA) & (a > b + ACNE_LEAK_MARGIN)
    return int(np.count_nonzero(acne)) / n, int(np.count_nonzero(leak)) / n


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
        texels), ``acne`` and ``leak`` (:func:`acne_leak`, fractions of all
        texels) as floats, and ``shadow_texels``, the number of texels in the
        reference shadow, as an int.
    """
    a, b = _pair(v, v_ref)
    acne, leak = acne_leak(a, b)
    return {
        "error": shadow_error(a, b, threshold=threshold),
        "rmse": rmse(a, b),
        "max": max_error(a, b),
        "acne": acne,
        "leak": leak,
        "shadow_texels": int(np.count_nonzero(shadow_mask(b, threshold=threshold))),
    }


# --------------------------------------------------------------------------
# Eye-view images
# --------------------------------------------------------------------------

#: The fields :func:`compare_images` reads, and their trailing shape after (H, W).
_IMAGE_FIELDS = (("visibility", ()), ("mask", ()), ("depth", ()), ("position", (3,)), ("mesh_id", ()))


@dataclass(frozen=True, eq=False)
class ImageComparison:
    """Visibility errors of an eye-view image against a reference one.

    Attributes
    ----------
    matched : int
        Pixels where both images see the same surface point (see
        :func:`compare_images`).
    matched_fraction : float
        ``matched`` over the pixels where either image hits a surface (1.0
        when neither hits anything).
    shadow_error : float
        Mean ``|V - V_ref|`` over the matched pixels the reference shadows
        (occlusion ``1 - V_ref`` above ``threshold``: umbra and penumbra),
        the light view's metric; 0.0 when the reference shadows none.
    shadowed : int
        Those pixels.
    acne, leak : float
        :func:`acne_leak` over the matched pixels: the fractions of them the
        method darkens where the reference is fully lit, and lightens where
        it is umbra, by more than 0.05.
    mean_abs, rmse, max_abs, p99_abs : float
        Mean, root-mean-square, largest and 99th-percentile ``|V - V_ref|``
        over all matched pixels, lit ones included (0.0 when none is
        matched).
    grain : float
        Per-pixel noise the reference does not have: the mean
        ``|V - box3x3(V)|`` over the reference's penumbra pixels (``0.02 <
        V_ref < 0.98``) whose 3x3 block is matched, minus the reference's own
        over the same pixels (0.0 when there are none). A method whose
        samples change from pixel to pixel draws grain; one that follows
        the geometry does not.
    mismatched : int
        Pixels where either image hits a surface but they are not matched.
    mask : numpy.ndarray, (H, W) bool
        The matched pixels.
    """

    matched: int
    matched_fraction: float
    shadow_error: float
    shadowed: int
    acne: float
    leak: float
    mean_abs: float
    rmse: float
    max_abs: float
    p99_abs: float
    grain: float
    mismatched: int
    mask: np.ndarray

    def __repr__(self) -> str:
        return (
            f"ImageComparison(matched={self.matched} ({self.matched_fraction:.1%}), "
            f"shadow_error={self.shadow_error:.4g} over {self.shadowed}, acne={self.acne:.2%}, "
            f"leak={self.leak:.2%}, mean_abs={self.mean_abs:.4g}, rmse={self.rmse:.4g}, max_abs={self.max_abs:.4g}, "
            f"p99_abs={self.p99_abs:.4g}, grain={self.grain:.2g}, mismatched={self.mismatched})"
        )


def _image_fields(image: Any, name: str) -> dict[str, np.ndarray]:
    """Read and shape-check an image's fields: (H, W) maps and (H, W, 3) positions."""
    fields: dict[str, np.ndarray] = {}
    for field, _trailing in _IMAGE_FIELDS:
        if not hasattr(image, field):
            raise TypeError(f"{name} has no attribute {field!r}")
        fields[field] = np.asarray(getattr(image, field))
    shape = fields["visibility"].shape
    if len(shape) != 2:
        raise ValueError(f"{name}.visibility must be 2-D (H, W), got shape {shape}")
    for field, trailing in _IMAGE_FIELDS:
        if fields[field].shape != shape + trailing:
            raise ValueError(f"{name}.{field} has shape {fields[field].shape}, expected {shape + trailing}")
    if fields["mask"].dtype != np.bool_:
        raise TypeError(f"{name}.mask must be boolean, got dtype {fields['mask'].dtype}")
    return fields


def _box_deviation(v: np.ndarray, where: np.ndarray) -> float:
    """Mean ``|v - box3x3(v)|`` over ``where`` (pixels away from the border)."""
    h, w = v.shape
    box = np.zeros((h - 2, w - 2))
    for dy in range(3):
        for dx in range(3):
            box += v[dy : dy + h - 2, dx : dx + w - 2]
    inner = where[1:-1, 1:-1]
    return float(np.abs(v[1:-1, 1:-1] - box / 9.0)[inner].mean())


def _grain(va: np.ndarray, vb: np.ndarray, matched: np.ndarray) -> float:
    """``ImageComparison.grain`` of full (H, W) visibilities."""
    h, w = matched.shape
    if h < 3 or w < 3:
        return 0.0
    block = np.ones((h - 2, w - 2), dtype=bool)
    for dy in range(3):
        for dx in range(3):
            block &= matched[dy : dy + h - 2, dx : dx + w - 2]
    where = np.zeros_like(matched)
    where[1:-1, 1:-1] = block
    where &= (vb > 0.02) & (vb < 0.98)
    if not where[1:-1, 1:-1].any():
        return 0.0
    va = np.where(matched, va, 0.0)
    vb = np.where(matched, vb, 0.0)
    return _box_deviation(va, where) - _box_deviation(vb, where)


def compare_images(
    image: Any, reference: Any, *, position_tol: float = 1e-4, threshold: float = DEFAULT_THRESHOLD
) -> ImageComparison:
    """Visibility errors of an eye-view image over the pixels that see the same point.

    A pixel is *matched* when both images hit a surface there (``mask``),
    the same mesh (``mesh_id``), at positions within ``position_tol`` times
    the reference's distance: ``|position - position_ref| <= position_tol *
    depth_ref``. Only matched pixels are compared, so silhouettes that the
    two renderers place differently do not count as shadow errors; they show
    up in ``matched_fraction`` and ``mismatched`` instead.

    Parameters
    ----------
    image, reference : object
        Anything with ``visibility``, ``mask``, ``depth`` ((H, W)),
        ``position`` ((H, W, 3)) and ``mesh_id`` ((H, W)), e.g. a
        :class:`softshadow.reference.ReferenceImage`.
    position_tol : float, optional
        Tolerance on the positions, relative to the reference depth.
    threshold : float, optional
        Occlusion above which a reference pixel is in shadow (as
        :func:`shadow_mask`).

    Returns
    -------
    ImageComparison

    Raises
    ------
    ValueError
        On a shape mismatch (naming the argument and field), a negative or
        non-finite ``position_tol``, a ``threshold`` outside [0, 1), or a NaN
        or inf visibility at a matched pixel.
    """
    threshold = _threshold(threshold)
    tol = float(position_tol)
    if not (np.isfinite(tol) and tol >= 0.0):
        raise ValueError(f"position_tol must be finite and non-negative, got {position_tol}")
    a = _image_fields(image, "image")
    b = _image_fields(reference, "reference")
    if a["visibility"].shape != b["visibility"].shape:
        raise ValueError(
            f"reference.visibility has shape {b['visibility'].shape} but image.visibility has {a['visibility'].shape}"
        )
    both = a["mask"] & b["mask"] & (a["mesh_id"] == b["mesh_id"])
    # Compare positions only where both hit (elsewhere they may be NaN).
    distance = np.full(both.shape, np.inf)
    pa = a["position"][both].astype(np.float64)
    pb = b["position"][both].astype(np.float64)
    distance[both] = np.linalg.norm(pa - pb, axis=-1)
    with np.errstate(invalid="ignore"):
        matched = both & (distance <= tol * b["depth"].astype(np.float64))
    either = int(np.count_nonzero(a["mask"] | b["mask"]))
    count = int(np.count_nonzero(matched))
    va = a["visibility"][matched].astype(np.float64)
    vb = b["visibility"][matched].astype(np.float64)
    errors = np.abs(va - vb)
    if not np.all(np.isfinite(errors)):
        raise ValueError("image.visibility or reference.visibility is NaN or inf at a matched pixel")
    in_shadow = (1.0 - vb) > threshold
    shadowed = int(np.count_nonzero(in_shadow))
    acne, leak = acne_leak(va, vb)
    if count:
        mean_abs = float(errors.mean())
        rmse_value = float(np.sqrt(np.mean(errors**2)))
        max_abs = float(errors.max())
        p99_abs = float(np.percentile(errors, 99))
    else:
        mean_abs = rmse_value = max_abs = p99_abs = 0.0
    return ImageComparison(
        matched=count,
        matched_fraction=count / either if either else 1.0,
        shadow_error=float(errors[in_shadow].mean()) if shadowed else 0.0,
        shadowed=shadowed,
        acne=acne,
        leak=leak,
        mean_abs=mean_abs,
        rmse=rmse_value,
        max_abs=max_abs,
        p99_abs=p99_abs,
        grain=_grain(a["visibility"].astype(np.float64), b["visibility"].astype(np.float64), matched),
        mismatched=either - count,
        mask=matched,
    )
