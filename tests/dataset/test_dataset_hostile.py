"""The dataset command against a hostile user (issue 30): links out of
``--out``, out-of-range arguments, a full or read-only disk, broken mesh
files, a damaged ``dataset.json``, and a main process killed on its own.

Tests run as root, where chmod stops nothing: storage errors are injected
by patching the EXR writer, as in test_dataset_faults.py.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import softshadow.io
from softshadow.dataset import OutputError, SpecError, StorageError, check_output, load_spec, run
from softshadow.dataset import item as item_module
from softshadow.dataset.cli import main
from softshadow.dataset.files import sha256_file
from softshadow.dataset.manifest import read_manifest

from .test_dataset_faults import SMALL, item_hashes, write_spec

TINY = SMALL.replace("count = 6", "count = 3").replace("previews = true", "previews = false")


def cli(args: list[str]) -> int:
    """The command's exit code, whether it returns it or argparse exits with it."""
    try:
        return main(args)
    except SystemExit as e:
        return int(e.code or 0)


# --------------------------------------------------------------------------
# 1. Nothing is read or written through a link out of --out
# --------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["manifest.jsonl", "dataset.json", "spec.toml.tmp", "dataset.json.tmp"])
def test_a_bookkeeping_file_linking_outside_out_is_never_written_through(tmp_path, name):
    spec = load_spec(write_spec(tmp_path, TINY))
    out = tmp_path / "out"
    run(spec, out, progress=False)
    outside = tmp_path / "outside.txt"
    outside.write_text("precious\n")
    target = out / name
    target.unlink(missing_ok=True)
    os.symlink(outside, target)
    try:
        run(spec, out, count=4, progress=False)
    except OutputError as e:
        assert name in str(e) and "symbolic link" in str(e)
    assert outside.read_text() == "precious\n"


def test_a_lock_linking_to_a_missing_outside_path_creates_nothing(tmp_path, capsys):
    spec_path = write_spec(tmp_path, TINY)
    out = tmp_path / "out"
    out.mkdir()
    os.symlink(tmp_path / "created-outside", out / "lock")
    assert cli(["run", str(spec_path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "lock" in err and "symbolic link" in err
    assert not (tmp_path / "created-outside").exists()


def test_check_reads_no_file_a_manifest_entry_leads_out_of(tmp_path):
    spec = load_spec(write_spec(tmp_path, TINY))
    out = tmp_path / "out"
    run(spec, out, progress=False)
    secret = tmp_path / "secret.txt"
    secret.write_text("not the dataset's\n")
    lines = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    lines[0]["files"]["../secret.txt"] = sha256_file(str(secret))
    (out / "manifest.jsonl").write_text("".join(json.dumps(r) + "\n" for r in lines))
    report = check_output(str(out))
    assert 0 in report.broken and "../secret.txt" in report.broken[0] and "outside --out" in report.broken[0]


def test_an_item_file_replaced_by_a_link_is_broken_and_redone(tmp_path):
    spec = load_spec(write_spec(tmp_path, TINY))
    out = tmp_path / "out"
    run(spec, out, progress=False)
    exr = out / "items" / "00000" / "00000001.exr"
    copy = tmp_path / "copy.exr"
    copy.write_bytes(exr.read_bytes())
    exr.unlink()
    os.symlink(copy, exr)  # same bytes, but outside --out
    report = check_output(str(out))
    assert 1 in report.broken and "symbolic link" in report.broken[1]
    again = run(spec, out, progress=False)
    assert again.done == 1 and not exr.is_symlink()
    assert check_output(str(out)).ok


def test_a_shard_folder_linking_outside_out_is_refused_before_any_write(tmp_path):
    spec = load_spec(write_spec(tmp_path, TINY))
    out = tmp_path / "out"
    (out / "items").mkdir(parents=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep.tmp-1-2").write_text("not ours to sweep")
    os.symlink(elsewhere, out / "items" / "00000")
    with pytest.raises((OutputError, ValueError), match="outside --out"):
        run(spec, out, progress=False)
    assert sorted(p.name for p in elsewhere.iterdir()) == ["keep.tmp-1-2"]


# --------------------------------------------------------------------------
# 2. Out-of-range arguments are refused before any work
# --------------------------------------------------------------------------

BAD_ARGS = [
    (["--window", "-3"], "--window", "[1, 100000]"),
    (["--window", "0"], "--window", "[1, 100000]"),
    (["--threads", "100000"], "--threads", "[1, 1024]"),
    (["--threads", "0"], "--threads", "[1, 1024]"),
    (["--workers", "0"], "--workers", "[1, 1024]"),
    (["--workers", "5000"], "--workers", "[1, 1024]"),
    (["--retries", "-1"], "--retries", "[0, 100]"),
    (["--retries", "101"], "--retries", "[0, 100]"),
    (["--count", "0"], "--count", "[1, 100000000]"),
    (["--count", "1000000000"], "--count", "[1, 100000000]"),
    (["--window", "many"], "--window", "[1, 100000]"),
]


@pytest.mark.timeout(30)  # --window -3 used to spin for ever
@pytest.mark.parametrize(("args", "name", "allowed"), BAD_ARGS, ids=[" ".join(a) for a, _, _ in BAD_ARGS])
def test_an_out_of_range_argument_is_refused_up_front(tmp_path, capsys, args, name, allowed):
    spec_path = write_spec(tmp_path, TINY)
    out = tmp_path / "out"
    assert cli(["run", str(spec_path), "--out", str(out), "--quiet", *args]) == 2
    err = capsys.readouterr().err
    assert name in err and allowed in err
    assert not out.exists()


@pytest.mark.timeout(30)
@pytest.mark.parametrize(("keyword", "value"), [("window", -3), ("window", 0), ("threads", 100_000), ("threads", 0)])
def test_the_library_refuses_them_too(tmp_path, keyword, value):
    spec = load_spec(write_spec(tmp_path, TINY))
    with pytest.raises(ValueError, match=f"{keyword}: must be an integer in"):
        run(spec, tmp_path / "out", workers=2, progress=False, **{keyword: value})
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------------
# 3. A full, over-quota or read-only disk stops the run
# --------------------------------------------------------------------------

STORAGE_FAILURES = [
    (RuntimeError('Cannot write image file "x.exr". No space left on device'), "No space left on device"),
    (RuntimeError("Error writing x.exr: Disk quota exceeded"), "Disk quota exceeded"),
    (RuntimeError('Cannot open image file "x.exr". Read-only file system.'), "Read-only file system"),
    (OSError(errno.EROFS, os.strerror(errno.EROFS)), os.strerror(errno.EROFS)),
    (OSError(errno.EDQUOT, os.strerror(errno.EDQUOT)), os.strerror(errno.EDQUOT)),
]


@pytest.mark.parametrize(
    ("error", "what"), STORAGE_FAILURES, ids=[w for _, w in STORAGE_FAILURES[:3]] + ["EROFS", "EDQUOT"]
)
def test_a_full_or_read_only_disk_stops_the_run_whatever_the_exception(tmp_path, monkeypatch, capsys, error, what):
    spec_path = write_spec(tmp_path, TINY)
    real = softshadow.io.write_exr
    writes = []

    def failing(path, channels, **kw):
        writes.append(path)
        if len(writes) == 2:  # item 0's image is written; item 1's fails
            raise error
        real(path, channels, **kw)

    monkeypatch.setattr(softshadow.io, "write_exr", failing)
    out = tmp_path / "out"
    assert cli(["run", str(spec_path), "--out", str(out), "--quiet", "--retries", "5"]) == 1
    err = capsys.readouterr().err
    assert len(writes) == 2, "no retry against a full disk"
    assert "rerun" in err and "resume" in err and "Traceback" not in err
    assert what in err
    assert "00000001.exr" in err  # the file it was writing
    assert all(r["status"] == "done" for r in read_manifest(str(out)).values())  # no item recorded as failed
    monkeypatch.setattr(softshadow.io, "write_exr", real)
    assert run(load_spec(spec_path), out, progress=False).done == 2


def test_a_full_disk_says_to_free_space_and_rerun_the_same_command(tmp_path, monkeypatch):
    spec = load_spec(write_spec(tmp_path, TINY))

    def full(path, channels, **kw):
        raise RuntimeError(f'Cannot write image file "{path}". No space left on device')

    monkeypatch.setattr(softshadow.io, "write_exr", full)
    with pytest.raises(StorageError) as info:
        run(spec, tmp_path / "out", progress=False)
    message = str(info.value)
    assert "free space" in message.lower() and "rerun the same command" in message
    assert ".tmp-" not in message  # the file's own name, not its temporary one


@pytest.mark.parametrize(
    "error",
    [
        PermissionError(errno.EACCES, os.strerror(errno.EACCES), "ITEMS"),
        RuntimeError('Cannot open image file "ITEMS". Permission denied.'),
    ],
    ids=["PermissionError", "OpenEXR's RuntimeError"],
)
def test_a_forbidden_items_folder_names_the_path(tmp_path, monkeypatch, error):
    spec = load_spec(write_spec(tmp_path, TINY))
    folder = tmp_path / "out" / "items" / "00000"

    def forbidden(path, channels, **kw):
        if isinstance(error, OSError):
            raise PermissionError(error.errno, error.strerror, str(folder))
        raise RuntimeError(str(error).replace("ITEMS", str(path)))

    monkeypatch.setattr(softshadow.io, "write_exr", forbidden)
    with pytest.raises(StorageError) as info:
        run(spec, tmp_path / "out", progress=False)
    message = str(info.value)
    assert "write writing" not in message
    assert "Permission denied" in message and str(folder) in message


# --------------------------------------------------------------------------
# 5. A mesh file that cannot be read is reported once, naming it
# --------------------------------------------------------------------------

BROKEN_MESHES = {
    "bad.ply": (b"hello", "Not a ply file"),
    "bad.glb": (b"glTFjunkjunkjunk", "GLTF"),
    "bad.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", "out of bounds"),
    "bad.off": (b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99\n", "face index"),
    "empty.stl": (b"", "no triangles"),
}


def _mesh_spec(folder: Path, path: str) -> Path:
    obj = f'[[objects]]\nkind = "mesh"\npath = "{path}"\n\n[[lights]]'
    return write_spec(folder, TINY.replace("[[lights]]", obj, 1))


@pytest.mark.parametrize("name", sorted(BROKEN_MESHES))
def test_a_broken_mesh_file_is_refused_once_naming_it_and_the_reader(tmp_path, monkeypatch, capsys, name):
    pytest.importorskip("trimesh")
    data, complaint = BROKEN_MESHES[name]
    (tmp_path / name).write_bytes(data)
    spec_path = _mesh_spec(tmp_path, name)
    renders = []
    real = item_module.render_item
    monkeypatch.setattr(item_module, "render_item", lambda *a: renders.append(a) or real(*a))
    out = tmp_path / "out"
    assert cli(["run", str(spec_path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert str(tmp_path / name) in err and complaint in err
    assert err.count(name) == 1 and not renders and not out.exists()


def test_a_mesh_failing_inside_an_item_is_not_retried(tmp_path, monkeypatch):
    from softshadow.dataset.build import MeshError

    spec = load_spec(write_spec(tmp_path, TINY))
    calls = []

    def broken(spec, k, threads):
        calls.append(k)
        raise MeshError(f"/meshes/{k}.ply: trimesh cannot read it (ValueError: Not a ply file!)")

    monkeypatch.setattr(item_module, "render_item", broken)
    summary = run(spec, tmp_path / "out", retries=2, progress=False)
    assert calls == [0, 1, 2] and summary.retried == 0
    assert "/meshes/1.ply" in summary.failed[1]
    assert read_manifest(str(tmp_path / "out"))[1]["attempts"] == 1


@pytest.mark.parametrize("kind", ["character device", "FIFO", "folder"])
def test_a_mesh_path_that_is_not_a_regular_file_says_what_it_is(tmp_path, kind):
    if kind == "character device":
        path = "/dev/zero"
    elif kind == "FIFO":
        os.mkfifo(tmp_path / "pipe.obj")
        path = "pipe.obj"
    else:
        (tmp_path / "meshes" / "sub.obj").mkdir(parents=True)  # a folder named like a mesh, in a mesh folder
        (tmp_path / "meshes" / "ok.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        path = "meshes"
    with pytest.raises(SpecError, match=rf"objects\[2\].path: .*is a {kind}, not a regular file"):
        load_spec(_mesh_spec(tmp_path, path))


# --------------------------------------------------------------------------
# 6. A damaged dataset.json says how to recover
# --------------------------------------------------------------------------

DAMAGED = ['{"format": 1, "spec_hash": ', "[1, 2]", '{"format": 1}', '{"format": 1, "count": -4}']


@pytest.mark.parametrize("text", DAMAGED, ids=["cut short", "not an object", "no fields", "bad count"])
def test_a_damaged_dataset_json_says_how_to_recover(tmp_path, capsys, text):
    spec_path = write_spec(tmp_path, TINY)
    out = tmp_path / "out"
    assert cli(["run", str(spec_path), "--out", str(out), "--quiet"]) == 0
    (out / "dataset.json").write_text(text)
    for command in (["check", str(out)], ["run", str(spec_path), "--out", str(out), "--quiet"]):
        assert cli(command) == 2
        err = capsys.readouterr().err
        assert "dataset.json" in err and "delete" in err and "rerun" in err, err
    # The advice works: delete it, rerun the same command.
    (out / "dataset.json").unlink()
    again = run(load_spec(spec_path), out, progress=False)
    assert again.skipped == 3 and check_output(str(out)).ok


def test_without_dataset_json_the_items_of_another_spec_are_not_taken_for_complete(tmp_path):
    first = load_spec(write_spec(tmp_path / "a", TINY))
    other = load_spec(write_spec(tmp_path / "b", TINY.replace("seed = 5", "seed = 6")))
    out = tmp_path / "out"
    run(first, out, progress=False)
    (out / "dataset.json").unlink()
    summary = run(other, out, progress=False)
    assert summary.done == 3 and summary.skipped == 0
    assert item_hashes(out) == item_hashes(_fresh(other, tmp_path / "fresh"))


def _fresh(spec, out: Path) -> Path:
    run(spec, out, progress=False)
    return out


# --------------------------------------------------------------------------
# 4. Workers die with the main process
# --------------------------------------------------------------------------


def _state(pid: int) -> str | None:
    """A process's state letter from /proc (None once it is gone)."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return text.rpartition(")")[2].split()[0]


def _alive(pid: int) -> bool:
    return _state(pid) not in (None, "Z", "X")  # a zombie is dead; whoever adopted it may never reap it


def _descendants(root: int) -> set[int]:
    parents: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                fields = Path(f"/proc/{entry}/stat").read_text().rpartition(")")[2].split()
            except (FileNotFoundError, ProcessLookupError):
                continue
            parents[int(entry)] = int(fields[1])
    found, frontier = set(), {root}
    while frontier:
        frontier = {pid for pid, ppid in parents.items() if ppid in frontier} - found
        found |= frontier
    return found


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="finds the workers through /proc")
def test_workers_die_with_a_sigkilled_main_process_and_the_run_resumes(tmp_path):
    count = 60
    spec_path = write_spec(tmp_path, TINY.replace("count = 3", f"count = {count}"))
    killed = tmp_path / "killed"
    cmd = [sys.executable, "-m", "softshadow.dataset", "run", str(spec_path), "--out", str(killed)]
    proc = subprocess.Popen(
        [*cmd, "--quiet", "--workers", "3", "--threads", "1"],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    workers: set[int] = set()
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if len(read_manifest(str(killed))) >= 3:
                break
            time.sleep(0.01)
        workers = {pid for pid in _descendants(proc.pid) if _alive(pid)}
        assert proc.poll() is None and len(workers) >= 3, "the kill must land while workers run"
        os.kill(proc.pid, signal.SIGKILL)  # the main process only
        proc.wait()
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and any(_alive(pid) for pid in workers):
            time.sleep(0.05)
        assert not [pid for pid in workers if _alive(pid)], "workers outlived their main process by 5 s"
    finally:
        for pid in workers | {proc.pid}:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    done_at_kill = len(check_output(str(killed)).complete)
    assert done_at_kill < count
    assert subprocess.run([*cmd, "--quiet"], capture_output=True).returncode == 0  # the same command resumes
    whole = _fresh(load_spec(spec_path), tmp_path / "whole")
    assert item_hashes(killed) == item_hashes(whole)
    assert check_output(str(killed)).ok


ORPHAN = """
import os, sys, time
from softshadow.dataset import lifeline

pid = os.fork()
if pid == 0:
    lifeline.die_with_parent(prctl=False)  # the watchdog alone, as where prctl is missing
    with open(sys.argv[1] + ".tmp", "w") as f:
        f.write(str(os.getpid()))
    os.replace(sys.argv[1] + ".tmp", sys.argv[1])
    time.sleep(60)
    os._exit(0)
while not os.path.exists(sys.argv[1]):
    time.sleep(0.01)
os._exit(0)  # the parent dies; its child must follow
"""


@pytest.mark.skipif(not hasattr(os, "fork") or not os.path.isdir("/proc/self"), reason="forks; reads /proc")
def test_the_watchdog_alone_ends_a_worker_whose_parent_died(tmp_path):
    marker = tmp_path / "child.pid"
    subprocess.run([sys.executable, "-c", ORPHAN, str(marker)], check=True, timeout=60)
    child = int(marker.read_text())
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and _alive(child):
        time.sleep(0.05)
    alive = _alive(child)
    if alive:
        os.kill(child, signal.SIGKILL)
    assert not alive, "the orphan outlived its parent by 5 s"
