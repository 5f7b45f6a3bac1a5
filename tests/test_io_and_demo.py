"""EXR/PNG writing and the demo (the README's main job: the eye view beside Mitsuba) end to end."""

import struct

import numpy as np
import pytest
from _png import decode_grey_png

from softshadow import io
from softshadow.experiments.demo import main


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


def png_size(path):
    """(W, H) from a PNG's IHDR."""
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


def test_demo_renders_the_eye_view_beside_mitsuba(tmp_path, capsys):
    pytest.importorskip("OpenEXR")
    pytest.importorskip("mitsuba")
    pytest.importorskip("matplotlib")
    import softshadow as ss
    from softshadow.scenes import eye_view

    assert main(["--out", str(tmp_path), "--resolution", "96", "72", "--samples", "16"]) == 0
    out = capsys.readouterr().out
    assert "first_hits" in out and "Mitsuba reference" in out
    # The EXR is softshadow's image of the built-in scene, every channel.
    img = io.read_exr(tmp_path / "bunny_on_floor.exr")
    assert img["V"].shape == (72, 96)
    assert {"V", "depth", "mesh_id", "mask", "position.x", "normal.z"} <= set(img)
    scene, light, camera = eye_view.bunny_on_floor((96, 72))
    np.testing.assert_array_equal(img["V"], ss.render(scene, light, camera).visibility)
    ref = io.read_exr(tmp_path / "bunny_on_floor_reference.exr")
    assert set(ref) == {"V", "mask"} and ref["V"].shape == (72, 96)
    # Both see the bunny and the floor, and Mitsuba's V is a multiple of 1/16.
    np.testing.assert_array_equal(ref["mask"], img["mask"])
    np.testing.assert_array_equal(ref["V"] * 16, np.round(ref["V"] * 16))
    err = float(out.split("matched pixels")[1].split("mean ")[1].split(";")[0])
    assert 0.0 < err < 0.05
    w, h = png_size(tmp_path / "demo.png")
    assert w > 1000 and h > 800  # the 2 x 2 figure


def test_demo_without_mitsuba_still_draws_its_figure(tmp_path, capsys):
    pytest.importorskip("OpenEXR")
    pytest.importorskip("matplotlib")
    assert main(["--out", str(tmp_path), "--resolution", "64", "48", "--samples", "0", "--method", "exact"]) == 0
    out = capsys.readouterr().out
    assert "Mitsuba" not in out and "-> Exact" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bunny_on_floor.exr", "demo.png"]
    w, h = png_size(tmp_path / "demo.png")
    assert w > h  # one row of two panels
    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path), "--resolution", "0", "48"])


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
