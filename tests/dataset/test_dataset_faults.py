"""The dataset command under faults: failing items, full or unwritable disks,
damaged output folders, hostile specs, and workers killed mid-item.

Tests run as root, where chmod does not stop writes: an unwritable folder is
a path under a regular file (NotADirectoryError) or a patched writer raising
EACCES, and a full disk a patched writer raising ENOSPC.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import signal
import sys
from pathlib import Path

import pytest

import softshadow.io
from softshadow.dataset import OutputError, SpecError, StorageError, check_output, load_spec, parse_spec, run
from softshadow.dataset import item as item_module
from softshadow.dataset.cli import main
from softshadow.dataset.manifest import read_manifest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

SMALL = """
seed = 5
count = 6

[[objects]]
kind = "box"
count = [1, 2]
scale = [0.4, 0.8]
x = [-1.0, 1.0]
z = [-1.0, 1.0]

[[objects]]
kind = "torus"
placement = "floating"
scale = 0.8

[[lights]]
kind = "rect"
size = [0.5, 1.5]

[camera]
resolution = [64, 48]

[method]
name = "bitmask"
options = { samples = 64 }
map_resolution = 64

[outputs]
previews = true
"""


def write_spec(folder: Path, text: str = SMALL) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / "spec.toml"
    p.write_text(text)
    return p


def item_hashes(out: Path) -> dict[str, str]:
    return {
        str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted((out / "items").rglob("*"))
        if p.is_file()
    }


def exr(out: Path, k: int) -> Path:
    return out / "items" / "00000" / f"{k:08d}.exr"


# --------------------------------------------------------------------------
# Failing items
# --------------------------------------------------------------------------


def test_a_failing_item_is_retried_then_reported_and_the_run_goes_on(tmp_path, monkeypatch):
    spec = load_spec(write_spec(tmp_path))
    real = item_module.render_item
    calls: dict[int, int] = {}

    def flaky(spec, k, threads):
        calls[k] = calls.get(k, 0) + 1
        if k == 2 or (k == 4 and calls[k] == 1):
            raise RuntimeError(f"injected failure of item {k}")
        return real(spec, k, threads)

    monkeypatch.setattr(item_module, "render_item", flaky)
    out = tmp_path / "out"
    summary = run(spec, out, retries=2, progress=False)
    assert calls[2] == 3 and calls[4] == 2  # 1 + retries attempts; a success stops retrying
    assert summary.done == 5 and summary.retried == 3
    assert list(summary.failed) == [2] and "injected failure of item 2" in summary.failed[2]
    records = read_manifest(str(out))
    assert records[2]["status"] == "failed" and records[2]["attempts"] == 3
    assert records[4]["status"] == "done" and records[4]["attempts"] == 2
    report = check_output(str(out))
    assert report.missing == [2] and "injected failure" in report.failed[2]
    assert report.complete == [0, 1, 3, 4, 5]
    assert not exr(out, 2).exists()

    monkeypatch.setattr(item_module, "render_item", real)
    again = run(spec, out, progress=False)  # a rerun retries what failed
    assert (again.done, again.skipped) == (1, 5)
    assert check_output(str(out)).ok
    assert item_hashes(out) == item_hashes(_fresh(spec, tmp_path / "fresh"))


def _fresh(spec, out: Path) -> Path:
    run(spec, out, progress=False)
    return out


def test_the_cli_exit_code_says_items_failed(tmp_path, monkeypatch, capsys):
    spec_path = write_spec(tmp_path)

    def broken(spec, k, threads):
        raise ValueError("always")

    monkeypatch.setattr(item_module, "render_item", broken)
    assert (
        main(["run", str(spec_path), "--out", str(tmp_path / "out"), "--count", "2", "--retries", "0", "--quiet"]) == 1
    )
    assert "2 failed" in capsys.readouterr().out


# --------------------------------------------------------------------------
# Storage
# --------------------------------------------------------------------------


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EACCES])
def test_a_full_or_forbidden_disk_stops_the_run_and_nothing_half_written_counts(tmp_path, monkeypatch, code):
    spec = load_spec(write_spec(tmp_path))
    real = softshadow.io.write_exr
    writes = []

    def failing(path, channels, **kw):
        writes.append(path)
        if len(writes) == 3:
            Path(path).write_bytes(b"\x76\x2f\x31\x01 half")  # a partial file, then the error
            raise OSError(code, os.strerror(code), str(path))
        real(path, channels, **kw)

    monkeypatch.setattr(softshadow.io, "write_exr", failing)
    out = tmp_path / "out"
    with pytest.raises(StorageError, match=os.strerror(code)) as info:
        run(spec, out, retries=5, progress=False)
    assert "rerun the same command to resume" in str(info.value) and "2 items" in str(info.value)
    assert len(writes) == 3  # no retry against a full disk
    report = check_output(str(out))
    assert report.complete == [0, 1] and report.missing == [2, 3, 4, 5] and not report.broken
    leftovers = sorted(p.name for p in (out / "items" / "00000").iterdir())
    assert all(n.startswith(("00000000.", "00000001.")) for n in leftovers), leftovers  # no temporary file

    monkeypatch.setattr(softshadow.io, "write_exr", real)
    assert run(spec, out, progress=False).done == 4
    assert check_output(str(out)).ok


def test_the_cli_reports_a_full_disk(tmp_path, monkeypatch, capsys):
    spec_path = write_spec(tmp_path)

    def full(path, channels, **kw):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(softshadow.io, "write_exr", full)
    assert main(["run", str(spec_path), "--out", str(tmp_path / "out"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "No space left on device" in err and "ENOSPC" in err


def test_an_output_folder_under_a_file_is_refused_with_a_clear_error(tmp_path, capsys):
    spec_path = write_spec(tmp_path)
    (tmp_path / "plain").write_text("a file, not a folder")
    assert main(["run", str(spec_path), "--out", str(tmp_path / "plain" / "data"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "out: cannot create or write" in err and "Not a directory" in err
    with pytest.raises(OutputError, match="cannot create"):
        run(load_spec(spec_path), tmp_path / "plain" / "data", progress=False)


def test_an_items_folder_linking_outside_out_is_refused(tmp_path):
    spec = load_spec(write_spec(tmp_path))
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "elsewhere").mkdir()
    os.symlink(tmp_path / "elsewhere", out / "items")
    with pytest.raises(ValueError, match="outside --out"):
        run(spec, out, progress=False)
    assert not list((tmp_path / "elsewhere").iterdir())


def test_a_second_run_into_a_locked_folder_is_refused(tmp_path):
    from softshadow.dataset.manifest import Output

    spec = load_spec(write_spec(tmp_path))
    with Output(str(tmp_path / "out"), spec, 6), pytest.raises(OutputError, match="another run"):
        run(spec, tmp_path / "out", progress=False)


# --------------------------------------------------------------------------
# check
# --------------------------------------------------------------------------


def test_check_finds_every_missing_or_corrupted_item(tmp_path, capsys):
    spec = load_spec(write_spec(tmp_path, SMALL.replace("count = 6", "count = 8")))
    out = tmp_path / "out"
    run(spec, out, items=range(7), progress=False)  # item 7 never made
    items = out / "items" / "00000"
    (items / "00000001.exr").unlink()  # deleted
    with open(items / "00000002.exr", "r+b") as f:  # truncated
        f.truncate(f.seek(0, os.SEEK_END) // 2)
    (items / "00000003.json").write_text('{"k": 3, "seed": ')  # corrupt JSON
    data = bytearray((items / "00000004.exr").read_bytes())  # bytes flipped in the pixel data
    for i in range(len(data) - 40, len(data) - 8):
        data[i] ^= 0xFF
    (items / "00000004.exr").write_bytes(bytes(data))
    png = bytearray((items / "00000005.png").read_bytes())
    png[20] ^= 0x01  # one bit of a preview
    (items / "00000005.png").write_bytes(bytes(png))
    with open(out / "manifest.jsonl", "a") as f:
        f.write('{"k": 6, "status": "do')  # a manifest line cut short: ignored, item 6 stays complete

    report = check_output(str(out))
    assert report.complete == [0, 6]
    assert report.missing == [7]
    assert sorted(report.broken) == [1, 2, 3, 4, 5]
    assert "missing" in report.broken[1]
    assert "sha256" in report.broken[2] and "sha256" in report.broken[4] and "sha256" in report.broken[5]
    # Without the hashes the decoders still catch the truncation and the JSON.
    quick = check_output(str(out), hashes=False)
    assert "EXR" in quick.broken[2] and "JSON" in quick.broken[3]

    assert main(["check", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "2 of 8 items complete, 1 missing, 5 broken" in printed and "missing: 7" in printed

    # run --verify redoes the broken ones; the folder is whole again.
    repaired = run(spec, out, verify=True, progress=False)
    assert repaired.done == 6 and repaired.skipped == 2
    assert main(["check", str(out)]) == 0
    assert item_hashes(out) == item_hashes(_fresh(spec, tmp_path / "fresh"))


def test_check_of_a_folder_without_a_dataset(tmp_path, capsys):
    assert main(["check", str(tmp_path)]) == 2
    assert "holds no dataset" in capsys.readouterr().err


# --------------------------------------------------------------------------
# Hostile or malformed specs: refused on load, before any work
# --------------------------------------------------------------------------


def _set(path: str, value):
    """A change to the parsed SMALL spec: ``path`` is dotted (``camera.zoom``,
    ``objects.0.kind``); ``+lights`` appends ``value`` to the lights."""

    def change(d):
        if path.startswith("+"):
            d[path[1:]].append(value)
            return
        *parents, last = path.split(".")
        for key in parents:
            d = d[int(key)] if key.isdigit() else d.setdefault(key, {})
        d[int(last) if last.isdigit() else last] = value

    return change


NAN, INF = float("nan"), float("inf")
HOSTILE = [
    (_set("colour", 1), "colour: unknown field"),
    (_set("camera.zoom", 2), "camera.zoom: unknown field"),
    (_set("seed", "one"), "seed: must be an integer"),
    (_set("seed", -1), "seed: must be an integer"),
    (_set("count", 10**9), r"count: must be an integer in \[1, 100000000\]"),
    (_set("count", 0), "count: must be an integer"),
    (_set("camera.resolution", [100000, 48]), r"camera.resolution: must be \[width, height\], integers in \[1, 8192\]"),
    (_set("camera.resolution", [64.0, 48]), r"camera.resolution"),
    (_set("camera.fov_y", NAN), "camera.fov_y: must be a finite number"),
    (_set("camera.distance", [1.0, INF]), "camera.distance: must be a finite number"),
    (_set("camera.distance", [5.0, 1.0]), "camera.distance: .*low <= high"),
    (_set("camera.elevation", True), "camera.elevation: must be a finite number"),
    (_set("outputs.folder", "../escape"), "outputs.folder: must be one plain folder name inside --out"),
    (_set("outputs.folder", "/tmp/abs"), "outputs.folder"),
    (_set("outputs.folder", "a/b"), "outputs.folder"),
    (_set("outputs.folder", "manifest.jsonl"), "outputs.folder"),
    (_set("outputs.channels", ["visibility", "colour"]), "outputs.channels: unknown channel 'colour'"),
    (_set("outputs.previews", "yes"), "outputs.previews: must be true or false"),
    (_set("outputs.compression", "lzma"), r"outputs.compression: must be one of \['none', 'zip', 'zstd'\], got 'lzma'"),
    (_set("outputs.compression", 3), "outputs.compression: must be a string"),
    (_set("method.name", "fastest"), r"method.name: must be one of \['ssm', 'bitmask'"),
    (_set("method.options", {"samples": 3}), "method.options.samples: bitmask takes one of"),
    (_set("method.options", {"sample": 3}), "method.options.sample: unknown option of 'bitmask'"),
    (_set("method.map_resolution", 100000), "method.map_resolution"),
    (_set("method.backend", "tpu"), "method.backend: must be one of"),
    (_set("objects.0.kind", "teapot"), r"objects\[0\].kind: must be one of \['bunny', 'box'"),
    (_set("objects.0.scale", -1.0), r"objects\[0\].scale: must be a finite number"),
    (_set("objects.0.count", 5000), r"objects\[0\].count: must be an integer or \[low, high\]"),
    (_set("objects.0.height", 1.0), r'objects\[0\].height: only for placement = "floating"'),
    (_set("objects.0.albedo", [0.5, 1.5]), r"objects\[0\].albedo"),
    (_set("objects.0.stretch", [1.0, NAN, 1.0]), r"objects\[0\].stretch\[1\]"),
    (_set("objects.0.layout", "grid"), r'objects\[0\].count: only for layout = "random"'),
    (_set("+objects", {"kind": "box", "layout": "grid", "grid": [100, 100]}), r"objects\[2\].grid"),
    (_set("+objects", {"kind": "mesh", "path": "../../no/such/mesh.obj"}), r"objects\[2\].path: no such file"),
    (_set("+objects", {"kind": "mesh", "path": "spec.toml"}), r"objects\[2\].path: .* is not a mesh file"),
    (_set("+objects", {"kind": "mesh"}), r"objects\[2\].path: missing"),
    (_set("+lights", {"kind": "sun", "size": 1.0}), r'lights\[1\].size: only for kind = "rect"'),
    (_set("+lights", {"kind": "rect", "elevation": [10, 95]}), r"lights\[1\].elevation"),
    (_set("+lights", {"kind": "lamp"}), r"lights\[1\].kind: must be one of \['rect', 'disk', 'sphere', 'sun'\]"),
    (_set("lights.0.target", [0, 0, NAN]), r"lights\[0\].target"),
]


@pytest.mark.parametrize(("change", "message"), HOSTILE, ids=[m.split(":")[0] for _, m in HOSTILE])
def test_a_hostile_spec_is_refused_naming_the_field(tmp_path, change, message):
    data = tomllib.loads(SMALL)
    change(data)
    write_spec(tmp_path)  # the spec's folder, for relative mesh paths
    with pytest.raises(SpecError, match=message):
        parse_spec(data, folder=str(tmp_path))


def test_light_maps_of_methods_without_maps_are_refused(tmp_path):
    text = SMALL.replace('name = "bitmask"\noptions = { samples = 64 }\nmap_resolution = 64', 'name = "exact"')
    with pytest.raises(SpecError, match="outputs.light_maps: method 'exact' makes no light-view maps"):
        load_spec(write_spec(tmp_path, text.replace("previews = true", "light_maps = true")))


def test_a_hostile_spec_leaves_no_trace(tmp_path, capsys):
    spec_path = write_spec(tmp_path, SMALL.replace("[camera]\nresolution = [64, 48]", "[camera]\nresolution = [0, 48]"))
    out = tmp_path / "out"
    assert main(["run", str(spec_path), "--out", str(out), "--quiet"]) == 2
    assert "camera.resolution" in capsys.readouterr().err
    assert not out.exists()


def test_not_toml_and_wrong_shapes_are_refused(tmp_path):
    with pytest.raises(SpecError, match="not valid TOML"):
        load_spec(write_spec(tmp_path, "[camera\n"))
    with pytest.raises(SpecError, match="lights: must hold 1 to 16 tables"):
        parse_spec({"camera": {}})
    with pytest.raises(SpecError, match="objects: must be an array of tables"):
        parse_spec({"objects": 3, "lights": [{"kind": "sun"}], "camera": {}})
    with pytest.raises(SpecError, match="camera: missing"):
        parse_spec({"lights": [{"kind": "sun"}]})
    with pytest.raises(SpecError, match="an item would have no surface"):
        parse_spec({"ground": {"enabled": False}, "lights": [{"kind": "sun"}], "camera": {}})


def test_mesh_files_resolve_against_the_spec_folder(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    (tmp_path / "meshes").mkdir()
    trimesh.creation.icosphere(subdivisions=2).export(tmp_path / "meshes" / "ball.obj")
    trimesh.creation.cylinder(radius=0.3, height=1.0).export(tmp_path / "meshes" / "can.ply")
    text = SMALL.replace('[[objects]]\nkind = "torus"', '[[objects]]\nkind = "mesh"\npath = "meshes"\ncount = 3\n#')
    spec = load_spec(write_spec(tmp_path / "specs", text.replace('path = "meshes"', 'path = "../meshes"')))
    assert [Path(f).name for f in spec.objects[1].files] == ["ball.obj", "can.ply"]
    run(spec, tmp_path / "out", count=2, progress=False)
    record = json.loads((tmp_path / "out" / "items" / "00000" / "00000000.json").read_text())
    files = {o["file"] for o in record["objects"] if o["kind"] == "mesh"}
    assert files <= {"../meshes/ball.obj", "../meshes/can.ply"} and files
    # A changed mesh file is another spec.
    before = spec.hash
    trimesh.creation.icosphere(subdivisions=1).export(tmp_path / "meshes" / "ball.obj")
    changed = load_spec(tmp_path / "specs" / "spec.toml")
    assert changed.hash != before
    with pytest.raises(SpecError, match="another spec"):
        run(changed, tmp_path / "out", count=2, progress=False)


# --------------------------------------------------------------------------
# Workers killed mid-item
# --------------------------------------------------------------------------


def _kill_on_item(marker: str, victim: int) -> None:
    """Installed in every Dask worker process: the first worker to write item
    ``victim`` leaves a temporary file and SIGKILLs its own process."""
    from softshadow.dataset import item

    real = item.write_item_files

    def write(root, writers):
        rel = next(iter(writers))
        if f"/{victim:08d}." in rel and not os.path.exists(marker):
            with open(marker, "w") as f:
                f.write(str(os.getpid()))
            path = os.path.join(root, rel + ".tmp-dying")
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "wb") as f:
                f.write(b"half an item")
            os.kill(os.getpid(), signal.SIGKILL)
        return real(root, writers)

    item.write_item_files = write


def test_a_dask_worker_killed_mid_item_loses_nothing_and_duplicates_nothing(tmp_path):
    """A LocalCluster of 2 worker processes (processes=True): one is SIGKILLed
    while it writes item 3, by a patch installed in the workers with
    ``client.run``. This is a real death (the nanny restarts the process,
    the scheduler reschedules its tasks); a task raising once in a threaded
    cluster would only exercise our own retries (the test above does)."""
    distributed = pytest.importorskip("distributed")
    spec = load_spec(write_spec(tmp_path))
    marker = tmp_path / "killed.pid"
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        pids = set(client.run(os.getpid).values())
        client.run(_kill_on_item, str(marker), 3)
        summary = run(spec, tmp_path / "dask", dask=client, retries=0, progress=False)
        survivors = set(client.run(os.getpid).values())
    assert marker.exists() and int(marker.read_text()) in pids
    assert int(marker.read_text()) not in survivors  # that process really died
    assert summary.done == 6 and not summary.failed
    lines = [json.loads(line) for line in (tmp_path / "dask" / "manifest.jsonl").read_text().splitlines()]
    assert sorted(r["k"] for r in lines) == list(range(6)) and all(r["status"] == "done" for r in lines)
    report = check_output(str(tmp_path / "dask"))
    assert report.ok and not report.temporaries  # the dead worker's temporary file was swept
    assert item_hashes(tmp_path / "dask") == item_hashes(_fresh(spec, tmp_path / "local"))


class _KillingInit:
    """A picklable initializer for the local pool's workers: the usual one,
    then :func:`_kill_on_item`."""

    def __init__(self, marker: str, victim: int) -> None:
        self.marker, self.victim = marker, victim

    def __call__(self, threads: int) -> None:
        os.environ["SOFTSHADOW_THREADS"] = str(threads)
        _kill_on_item(self.marker, self.victim)


def test_a_local_worker_killed_mid_item_costs_only_its_items(tmp_path, monkeypatch):
    """The pool breaks when one of its processes dies (SIGKILL while writing
    item 3); the run rebuilds it and hands out again the items it held."""
    from softshadow.dataset import runner

    spec = load_spec(write_spec(tmp_path))
    marker = tmp_path / "killed.pid"
    monkeypatch.setattr(runner, "_init_worker", _KillingInit(str(marker), 3))
    summary = run(spec, tmp_path / "pool", workers=2, retries=2, progress=False)
    assert marker.exists()  # a worker died
    assert summary.done == 6 and not summary.failed and summary.retried >= 1
    lines = [json.loads(line) for line in (tmp_path / "pool" / "manifest.jsonl").read_text().splitlines()]
    assert sorted(r["k"] for r in lines) == list(range(6)) and all(r["status"] == "done" for r in lines)
    report = check_output(str(tmp_path / "pool"))
    assert report.ok and not report.temporaries
    assert item_hashes(tmp_path / "pool") == item_hashes(_fresh(spec, tmp_path / "local"))
