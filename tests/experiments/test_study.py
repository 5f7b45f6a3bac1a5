"""The study command runs end to end and writes its table and plots."""

import pytest

pytest.importorskip("matplotlib")
pytest.importorskip("mitsuba")


@pytest.mark.slow
def test_study_plane_on_a_small_map(tmp_path):
    from softshadow.experiments.study import main

    out = tmp_path / "study"
    assert (
        main(
            [
                "--out",
                str(out),
                "--quick",
                "--resolution",
                "64",
                "--repeats",
                "1",
                "--scenes",
                "square_plate",
                "--parts",
                "plane",
                "timings",
                "--reference-samples",
                "256",
            ]
        )
        == 0
    )
    md = (out / "study.md").read_text()
    assert "| square_plate | ssm | 2 passes, occluders 64² |" in md
    assert "| square_plate | exact | 16 samples |" in md
    assert "| square_plate | mitsuba | 16 samples |" in md
    assert "| square_plate | pcss | occluders 64² |" in md
    assert "| square_plate | smoothies | width 0.5, occluders 64² |" in md
    assert (out / "plane_square_plate.png").stat().st_size > 10_000
    assert (out / "time_vs_map_size.png").exists()
    # The plate is the paper's easy case: the SSM is nearly exact on it.
    row = next(line for line in md.splitlines() if "| square_plate | ssm | 2 passes, occluders 64² |" in line)
    assert float(row.split("|")[5]) < 0.02
    assert "| square_plate | auto | ssm, 2 passes, occluders 64² |" in md
    summary = md.split("### Summary")[1]
    assert "| square_plate |" in summary


def test_mitsuba_time_at_equal_error_follows_the_sample_law():
    from softshadow.experiments.points import Point, mitsuba_seconds_at

    # error = 0.4 / sqrt(k), time = k ms: the interpolation is exact inside
    # and the extrapolation keeps the law outside.
    pts = [Point("s", "mitsuba", f"{k} samples", k * 1e-3, 0.4 / k**0.5) for k in (4, 16, 64)]
    for k, outside in ((8, False), (30, False), (256, True), (2, True)):
        t, out = mitsuba_seconds_at(0.4 / k**0.5, pts)
        assert t == pytest.approx(k * 1e-3, rel=1e-9)
        assert out is outside


@pytest.mark.slow
def test_study_eye_view_and_scherzer_parts_write_tables_plots_and_the_readme_block(tmp_path):
    from softshadow.experiments.study import main

    out = tmp_path / "study"
    readme = tmp_path / "README.md"
    readme.write_text("intro\n<!-- study-summary:start -->\nold\n<!-- study-summary:end -->\nrest\n")
    args = ["--out", str(out), "--parts", "eye", "scherzer", "--eye-resolution", "64", "48", "--repeats", "1"]
    args += ["--eye-reference-samples", "64", "--eye-scenes", "city", "--readme", str(readme)]
    assert main(args) == 0
    md = (out / "study.md").read_text()
    for label in ("ssm", "exact 16", "pcss", "smoothies", "shadow map", "shadow map, PCF 3", "shadow map, blur 4"):
        assert f"| softshadow {label} |" in md
    assert "| Mitsuba | 16 samples |" in md
    for name in ("eye_city", "bias_acne_peter_panning", "aliasing_vs_resolution", "blur_iterations", "smoothie_width"):
        assert (out / f"{name}.png").stat().st_size > 10_000
    # Every bias method and map kind has its row; the uniform unfocused map
    # misclassifies something in the large city at 512².
    for label in ("SlopeScaleBias() (default)", "BackFaces()", "MidpointBias()", "LinearDepthBias()"):
        assert f"| {label} |" in md
    alias = [line.split("|")[1:-1] for line in md.split("### Aliasing")[1].split("###")[0].splitlines()]
    alias = [[c.strip() for c in row] for row in alias if row]
    head, at_512 = alias[0], next(row for row in alias if row[0] == "512")
    assert float(at_512[head.index("unfocused")]) > 0
    text = readme.read_text()
    assert text.startswith("intro\n<!-- study-summary:start -->\nFrom `python -m softshadow.experiments.study")
    assert "old" not in text and text.endswith("<!-- study-summary:end -->\nrest\n")
    assert "| shadow map, PCF |" in text
