"""The demo (the README's main job: the eye view beside Mitsuba) end to end."""

import struct

import numpy as np
import pytest

from softshadow import io
from softshadow.experiments.demo import main


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
    # The error is over the pixels Mitsuba shadows, acne and leaks beside it.
    line = out.split("error over shadowed pixels")[1].split("\n")[0]
    err = float(line.split("mean ")[1].split(";")[0])
    assert 0.0 < err < 0.05
    assert "acne" in line and "leaks" in line
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


def test_the_figure_shows_the_shaded_image_where_no_map_was_read():
    pytest.importorskip("matplotlib")
    import softshadow as ss
    from softshadow.experiments.demo import figure
    from softshadow.scenes import eye_view

    scene, light, camera = eye_view.bunny_on_floor((48, 36))
    img = ss.render(scene, light, camera, ss.Exact(samples=64))
    assert not img.shadow_maps
    panel = figure(img, 0.1).axes[-1]
    assert len(panel.images) == 1 and "shaded" in panel.get_title()
    shown = np.asarray(panel.images[0].get_array())
    assert shown.shape == (36, 48, 3) and 0.0 <= shown.min() and shown.max() <= 1.0 and shown.max() > 0.5
