"""EXR/PNG writing (softshadow.io) and the results' own writers, round trip."""

import numpy as np
import pytest
from _png import decode_grey_png

from softshadow import io


def read_png_grey(path):
    with open(path, "rb") as f:
        return decode_grey_png(f.read())


def test_png_round_trip(tmp_path):
    img = (np.arange(12 * 7) % 256).astype(np.uint8).reshape(7, 12)
    io.write_png(tmp_path / "a.png", img)
    np.testing.assert_array_equal(read_png_grey(tmp_path / "a.png"), img)
    with pytest.raises(TypeError, match="image"):
        io.write_png(tmp_path / "b.png", img.astype(np.float32))
    np.testing.assert_array_equal(io.to_uint8([0.0, 0.5, 1.0, np.nan, 2.0]), [0, 128, 255, 0, 255])


def test_exr_round_trip(tmp_path):
    pytest.importorskip("OpenEXR")
    v = np.random.default_rng(0).random((5, 9)).astype(np.float32)
    io.write_exr(tmp_path / "v.exr", {"V": v, "D": v * 2})
    back = io.read_exr(tmp_path / "v.exr")
    np.testing.assert_array_equal(back["V"], v)
    np.testing.assert_array_equal(back["D"], v * 2)
    with pytest.raises(ValueError, match="shape"):
        io.write_exr(tmp_path / "w.exr", {"A": v, "B": v[:2]})


def test_shadow_map_writes_all_its_maps(tmp_path):
    pytest.importorskip("OpenEXR")
    import softshadow as ss
    from softshadow import scenes

    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=(24, 16))
    sm.write_exr(tmp_path / "sm.exr")
    back = io.read_exr(tmp_path / "sm.exr")
    assert set(back) == {"V", "receiver", "occluder", "occluder_back"}
    np.testing.assert_array_equal(back["V"], sm.visibility)
    np.testing.assert_array_equal(back["occluder"], sm.occluder_depth)  # inf survives
    assert "24x16" in repr(sm) and "passes=2" in repr(sm)
