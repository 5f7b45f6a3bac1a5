"""Results that show themselves in a notebook (``_repr_png_``, ``plot()``) and
the quickstart notebook kept without outputs (pytest --nbmake runs it)."""

from __future__ import annotations

import io as _io
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from _png import decode_grey_png

import softshadow as ss
from softshadow.scenes import eye_view

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "quickstart.ipynb"


def expected_grey(visibility: np.ndarray, surface: np.ndarray) -> np.ndarray:
    """round(255 V) where there is a surface, 128 elsewhere (documented in
    softshadow._preview and the two ``_repr_png_`` docstrings)."""
    v = np.floor(np.clip(visibility.astype(np.float64), 0.0, 1.0) * 255.0 + 0.5)
    return np.where(surface, v, 128.0).astype(np.uint8)


def map_with_holes(w: int = 40, h: int = 24) -> ss.ShadowMap:
    """A w x h map from depth maps whose left w/5 columns have no receiver,
    with a small occluder in the middle."""
    rec = np.full((h, w), 3.0, np.float32)
    rec[:, : w // 5] = np.inf
    occ = np.full((h, w), np.inf, np.float32)
    occ[h // 3 : 2 * h // 3, 2 * w // 5 : 7 * w // 10] = 1.5
    return ss.soft_shadow_map_from_depth(occ, rec, light_size=(0.1, 0.1), extent=(0.5, 0.5))


@pytest.fixture(params=["pillow", "zlib"])
def encoder(request, monkeypatch):
    """Runs a test with Pillow's encoder and with the zlib fallback."""
    if request.param == "pillow":
        pytest.importorskip("PIL")
    else:
        monkeypatch.setitem(sys.modules, "PIL", None)  # `from PIL import ...` raises ImportError
    return request.param


def test_shadow_map_png_shows_the_visibility_and_grey_where_no_receiver(encoder):
    sm = map_with_holes()
    assert 0.0 < sm.visibility[:, 8:].min() < 1.0  # a shadow to see
    grey = decode_grey_png(sm._repr_png_())
    # 40 wide is enlarged 6 times (the largest factor within 256), values repeated.
    assert grey.shape == (24 * 6, 40 * 6)
    small = grey[::6, ::6]
    np.testing.assert_array_equal(grey, np.repeat(np.repeat(small, 6, 0), 6, 1))
    np.testing.assert_array_equal(small, expected_grey(sm.visibility, np.isfinite(sm.receiver_depth)))
    assert (small[:, :8] == 128).all() and (small[:, 8:] != 128).any()


def test_large_maps_are_subsampled_not_resampled(encoder):
    sm = map_with_holes(1100, 300)
    assert (sm.visibility < 1.0).any()  # a shadow to see
    grey = decode_grey_png(sm._repr_png_())
    # Step ceil(1100 / 512) = 3: every third texel, unchanged.
    assert grey.shape == (100, 367)
    np.testing.assert_array_equal(grey, expected_grey(sm.visibility, np.isfinite(sm.receiver_depth))[::3, ::3])


def test_image_png_shows_the_visibility_and_grey_where_no_surface(encoder):
    scene, light, camera = eye_view.bunny_on_floor((96, 72))
    img = ss.render(scene, light, camera, method="ssm")
    assert (~img.mask).any() and (img.visibility[img.mask] < 0.5).any()
    grey = decode_grey_png(img._repr_png_())
    assert grey.shape == (72 * 2, 96 * 2)
    np.testing.assert_array_equal(grey[::2, ::2], expected_grey(img.visibility, img.mask))
    assert (grey[::2, ::2][~img.mask] == 128).all()


def test_pillow_and_zlib_encode_the_same_pixels(monkeypatch):
    pytest.importorskip("PIL")
    sm = map_with_holes()
    with_pillow = sm._repr_png_()
    monkeypatch.setitem(sys.modules, "PIL", None)
    with_zlib = sm._repr_png_()
    np.testing.assert_array_equal(decode_grey_png(with_pillow), decode_grey_png(with_zlib))


def test_pillow_reads_the_png():
    pil = pytest.importorskip("PIL.Image")
    sm = map_with_holes()
    with pil.open(_io.BytesIO(sm._repr_png_())) as im:
        assert im.size == (240, 144) and im.mode == "L"


def test_shadow_map_plot_draws_the_visibility():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sm = map_with_holes()
    ax = sm.plot(title="holes")
    shown = np.asarray(ax.images[0].get_array())
    np.testing.assert_array_equal(shown[:, 8:], sm.visibility[:, 8:])
    assert (shown[:, :8] == 0.5).all()
    assert ax.get_title() == "holes"
    _, own = plt.subplots()
    assert sm.plot(own) is own and own.get_title() == repr(sm.method)
    plt.close("all")


def test_the_notebook_in_the_repository_has_no_outputs():
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code, "the notebook has code cells"
    for k, cell in enumerate(code):
        assert cell.get("outputs") == [], f"code cell {k} keeps outputs"
        assert cell.get("execution_count") is None, f"code cell {k} keeps an execution count"
