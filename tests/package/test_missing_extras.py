"""An optional dependency that is missing is named with the extra that
installs it (issue 30): no bare ``No module named 'tqdm'`` and no traceback.

``pip install softshadow`` brings numpy alone; pyproject.toml's extras
bring the rest (``io``: trimesh, OpenEXR; ``dataset``: those with tqdm,
dask[distributed], tomli). Each test blocks an import (``sys.modules[name]
= None`` makes ``import name`` fail) and checks the library's
MissingExtraError and the command's one line on stderr.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import io
from softshadow.dataset.cli import main

SPEC = """
count = 2

[[objects]]
kind = "box"
scale = 0.5

[[lights]]
kind = "sun"

[camera]
resolution = [32, 24]

[method]
name = "bitmask"
options = { samples = 16 }
"""

DATASET = 'pip install "softshadow[dataset]"'


def block(monkeypatch, *names: str) -> None:
    for name in names:
        monkeypatch.setitem(sys.modules, name, None)


def spec_file(folder: Path, text: str = SPEC) -> str:
    path = folder / "spec.toml"
    path.write_text(text)
    return str(path)


def command(args: list[str]) -> int:
    try:
        return main(args)
    except SystemExit as e:
        return int(e.code or 0)


def one_line_naming_the_extra(err: str, package: str, extra: str = DATASET) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert package in lines[0] and extra in lines[0], err


def test_run_without_tqdm_names_the_extra_and_quiet_needs_no_tqdm(tmp_path, monkeypatch, capsys):
    block(monkeypatch, "tqdm")
    spec = spec_file(tmp_path)
    assert command(["run", spec, "--out", str(tmp_path / "bar")]) == 2
    err = capsys.readouterr().err
    one_line_naming_the_extra(err, "tqdm")
    assert "--quiet" in err and not (tmp_path / "bar").exists()
    assert command(["run", spec, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0


def test_check_and_run_without_openexr_name_the_extra(tmp_path, monkeypatch, capsys):
    spec = spec_file(tmp_path)
    assert command(["run", spec, "--out", str(tmp_path / "out"), "--quiet"]) == 0
    capsys.readouterr()
    block(monkeypatch, "OpenEXR")
    assert command(["check", str(tmp_path / "out")]) == 2
    one_line_naming_the_extra(capsys.readouterr().err, "OpenEXR")
    assert command(["run", spec, "--out", str(tmp_path / "other"), "--quiet"]) == 2
    one_line_naming_the_extra(capsys.readouterr().err, "OpenEXR")
    assert not (tmp_path / "other").exists()


def test_run_on_dask_without_distributed_names_the_extra(tmp_path, monkeypatch, capsys):
    block(monkeypatch, "distributed")
    out = tmp_path / "out"
    assert command(["run", spec_file(tmp_path), "--out", str(out), "--quiet", "--dask", "local"]) == 2
    one_line_naming_the_extra(capsys.readouterr().err, "distributed")
    assert not out.exists()


def test_a_spec_without_a_toml_reader_names_the_extra(tmp_path, monkeypatch, capsys):
    block(monkeypatch, "tomllib", "tomli")
    assert command(["run", spec_file(tmp_path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    one_line_naming_the_extra(capsys.readouterr().err, "tomli")


def test_a_mesh_spec_without_trimesh_names_the_extra(tmp_path, monkeypatch, capsys):
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    text = SPEC.replace('kind = "box"', 'kind = "mesh"\npath = "tri.obj"')
    from softshadow.dataset import build

    build.base_mesh.cache_clear()  # another test may have read it
    block(monkeypatch, "trimesh")
    assert command(["run", spec_file(tmp_path, text), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    one_line_naming_the_extra(capsys.readouterr().err, "trimesh")


def test_the_library_raises_an_import_error_naming_the_extra(tmp_path, monkeypatch):
    block(monkeypatch, "trimesh", "OpenEXR")
    from softshadow._extras import MissingExtraError

    with pytest.raises(ModuleNotFoundError, match=r'Scene.from_trimesh needs trimesh.*pip install "softshadow\[io\]"'):
        ss.Scene.from_trimesh(tmp_path / "room.glb")
    with pytest.raises(MissingExtraError, match=r'write_exr needs OpenEXR.*pip install "softshadow\[io\]"'):
        io.write_exr(tmp_path / "a.exr", np.zeros((2, 2)))
    with pytest.raises(ImportError, match=r'read_exr needs OpenEXR.*"softshadow\[io\]"'):
        io.read_exr(tmp_path / "a.exr")


def test_the_installed_command_prints_one_line_and_no_traceback(tmp_path):
    """The real entry point in a fresh interpreter, tqdm blocked before anything imports it."""
    code = (
        "import sys; sys.modules['tqdm'] = None; "
        "from softshadow.dataset.cli import main; raise SystemExit(main(sys.argv[1:]))"
    )
    args = ["run", spec_file(tmp_path), "--out", str(tmp_path / "out")]
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    one_line_naming_the_extra(done.stderr, "tqdm")
