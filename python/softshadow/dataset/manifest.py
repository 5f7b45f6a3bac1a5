"""The output folder's bookkeeping: ``dataset.json``, ``spec.toml``, ``manifest.jsonl`` and the lock.

* ``spec.toml``: the spec's text as given; ``dataset.json``: its hash (the
  identity of the items: a different spec is refused in the same folder),
  the seed, the item count last asked for, the output folder, channels and
  resolution (what ``check`` expects).
* ``manifest.jsonl``: append-only, one JSON object per line, fsynced:
  ``{"k", "status": "done", "files": {path: sha256}, "seconds", "attempts"}``
  once every file of item k is in place, or ``{"k", "status": "failed",
  "error", "attempts"}``. For each k the last line counts. A line cut short
  by a crash is ignored (and the next append starts on a new line).
* ``lock``: held (``flock``) by the one run writing into the folder; the
  kernel drops it when that process dies, however it dies.

None of them is read or written through a link (``O_NOFOLLOW``; the
temporary files are made anew and renamed over the final names), and the
item folders must stay inside ``--out`` (:mod:`.files`). A ``dataset.json``
that is damaged is refused with the way back: delete it and rerun; a run
that finds it missing beside a manifest re-checks every item the manifest
lists against its spec (:attr:`Output.recovered`), so that the items of
another spec are never taken for its own.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import re
from typing import Any

from . import limits as L
from .fields import SpecError
from .files import inside, is_link_error, open_nofollow, write_new
from .spec import CHANNELS, FOLDER_NAME, Spec

FORMAT = 1
SPEC = "spec.toml"
DATASET = "dataset.json"
MANIFEST = "manifest.jsonl"
LOCK = "lock"


class OutputError(RuntimeError):
    """``--out`` cannot be used: not writable, locked, or another spec's dataset."""


class StorageError(RuntimeError):
    """The output folder cannot take more files (full, read-only, forbidden)."""


_RESUME = "Free space (or make the folder writable), then rerun the same command to resume"

MAX_DATASET_BYTES = 1 << 20
"""A ``dataset.json`` is a few hundred bytes; a larger one is damaged."""


def _describe(e: OSError) -> str:
    return f"{e.strerror or e} ({errno.errorcode.get(e.errno or 0, e.errno)})"


def _unusable(e: OSError, doing: str) -> OutputError:
    """OutputError for an OSError met opening ``--out``'s own files (a link says it is one)."""
    if is_link_error(e):
        return OutputError(f"out: {e.strerror}")
    return OutputError(f"out: {doing}: {_describe(e)}")


def write_json_atomic(path: str, value: Any) -> None:
    tmp = path + ".tmp"
    write_new(tmp, (json.dumps(value, indent=1, sort_keys=True) + "\n").encode())
    os.replace(tmp, path)  # replaces a link at ``path``, never follows it


def read_manifest(out: str) -> dict[int, dict[str, Any]]:
    """The last record of every item in the manifest (an empty dict if there is none)."""
    records: dict[int, dict[str, Any]] = {}
    path = os.path.join(out, MANIFEST)
    try:
        fd = open_nofollow(path, os.O_RDONLY)
    except FileNotFoundError:
        return records
    except OSError as e:
        raise _unusable(e, f"cannot read {path!r}") from e
    with open(fd, encoding="utf-8", errors="replace") as f:
        for line in f:
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line cut short by a crash
            if isinstance(rec, dict) and isinstance(rec.get("k"), int) and rec.get("status") in ("done", "failed"):
                records[rec["k"]] = rec
    return records


def damaged(path: str, why: str) -> OutputError:
    """The OutputError for a damaged ``dataset.json``, with the way back."""
    return OutputError(
        f"out: {path!r} is damaged: {why}. It is written by `softshadow-dataset run` from the spec (its text is in "
        f"{SPEC} beside it). To recover, delete {DATASET} and rerun the run command that made this folder: it writes "
        "the file again and re-checks every item of the manifest against that spec (an item of another spec is made "
        "again). Or run into a new --out."
    )


def _int_in(info: dict[str, Any], key: str, lo: int, hi: int) -> str | None:
    v = info.get(key)
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        return f"{key} must be an integer in [{lo}, {hi}], got {v!r}"
    return None


def _dataset_problem(info: Any) -> str | None:
    """Why a parsed ``dataset.json`` cannot be used (what ``check`` and a run rely on), or None."""
    if not isinstance(info, dict):
        return f"it holds a JSON {type(info).__name__}, not an object"
    if info.get("format") != FORMAT:
        return f"format must be {FORMAT}, got {info.get('format')!r}"
    if not isinstance(info.get("spec_hash"), str) or not re.fullmatch(r"[0-9a-f]{64}", info["spec_hash"]):
        return f"spec_hash must be a sha256 in hex, got {info.get('spec_hash')!r}"
    for key, lo, hi in (("seed", 0, L.MAX_SEED), ("count", 1, L.MAX_COUNT)):
        problem = _int_in(info, key, lo, hi)
        if problem:
            return problem
    folder = info.get("folder")
    if not isinstance(folder, str) or len(folder) > L.MAX_NAME or not FOLDER_NAME.match(folder):
        return f"folder must be one plain folder name, got {folder!r}"
    channels = info.get("channels")
    if not isinstance(channels, list) or not channels or not all(c in CHANNELS for c in channels):
        return f"channels must be a non-empty list of {CHANNELS}, got {channels!r}"
    res = info.get("resolution")
    if not (
        isinstance(res, list)
        and len(res) == 2
        and all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= L.MAX_SIDE for x in res)
    ):
        return f"resolution must be [width, height] in [1, {L.MAX_SIDE}], got {res!r}"
    for key, hi in (("item_digits", 20), ("shard", L.MAX_COUNT)):
        if key in info:
            problem = _int_in(info, key, 1, hi)
            if problem:
                return problem
    return None


def read_dataset(out: str) -> dict[str, Any]:
    """``dataset.json`` of an output folder, checked; OutputError if it is
    missing, a link, unreadable or damaged (saying how to recover)."""
    path = os.path.join(out, DATASET)
    try:
        fd = open_nofollow(path, os.O_RDONLY)
    except FileNotFoundError as e:
        raise OutputError(
            f"out: {out!r} holds no dataset ({DATASET} is missing). If `softshadow-dataset run` made items here, "
            f"rerun that command: it writes {DATASET} again (re-checking the items)"
        ) from e
    except OSError as e:
        raise _unusable(e, f"cannot read {path!r}") from e
    try:
        with open(fd, "rb") as f:
            raw = f.read(MAX_DATASET_BYTES + 1)
    except OSError as e:
        raise OutputError(f"out: cannot read {path!r}: {_describe(e)}") from e
    if len(raw) > MAX_DATASET_BYTES:
        raise damaged(path, f"it is larger than {MAX_DATASET_BYTES} bytes")
    try:
        info = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise damaged(path, f"it is not JSON ({e})") from e
    if isinstance(info, dict) and isinstance(info.get("format"), int) and info["format"] > FORMAT:
        raise OutputError(
            f"out: {path!r} is of format {info['format']}, written by a newer softshadow (this one reads format "
            f"{FORMAT}): upgrade softshadow"
        )
    problem = _dataset_problem(info)
    if problem:
        raise damaged(path, problem)
    return info


class Output:
    """An output folder opened for a run: locked, the spec checked and stored."""

    recovered: bool = False
    """``dataset.json`` was missing beside a manifest (deleted to recover
    from damage): the run must re-check the items it lists (``verify``)."""

    def __init__(self, out: str, spec: Spec, count: int) -> None:
        self.root = os.path.abspath(out)
        self.spec = spec
        try:
            os.makedirs(self.root, exist_ok=True)
            self._lock_fd = open_nofollow(os.path.join(self.root, LOCK), os.O_RDWR | os.O_CREAT)
        except OSError as e:
            raise _unusable(e, f"cannot create or write {self.root!r}") from e
        try:
            fcntl.flock(self._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as e:
            os.close(self._lock_fd)
            raise OutputError(f"out: another run is writing into {self.root!r} (its {LOCK} is held)") from e
        try:
            self._check_item_folders()
            self._claim(count)
            manifest = os.path.join(self.root, MANIFEST)
            self._manifest_fd = open_nofollow(manifest, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
            self._ends_with_newline = self._manifest_ends_cleanly(manifest)
        except OSError as e:
            self.close()
            raise _unusable(e, f"cannot write into {self.root!r}") from e
        except BaseException:
            self.close()
            raise

    def _check_item_folders(self) -> None:
        """``outputs.folder`` and its subfolders stay inside ``--out`` (the
        spec checked the name; a link must not lead out): ValueError before
        anything is written or swept."""
        name = self.spec.outputs.folder
        folder = inside(self.root, name)
        if os.path.isdir(folder):
            for entry in os.listdir(folder):
                if os.path.islink(os.path.join(folder, entry)):
                    inside(self.root, f"{name}/{entry}")

    def _claim(self, count: int) -> None:
        spec_hash = self.spec.hash
        path = os.path.join(self.root, DATASET)
        if os.path.lexists(path):
            info = read_dataset(self.root)
            if info["spec_hash"] != spec_hash:
                raise SpecError(
                    f"spec: {self.root!r} holds items of another spec (hash {info['spec_hash'][:12]}..., "
                    f"this one {spec_hash[:12]}...); use another --out"
                )
        else:
            try:
                self.recovered = os.lstat(os.path.join(self.root, MANIFEST)).st_size > 0
            except FileNotFoundError:
                pass
        info = {
            "format": FORMAT,
            "spec_hash": spec_hash,
            "seed": self.spec.seed,
            "count": count,
            "folder": self.spec.outputs.folder,
            "channels": list(self.spec.outputs.channels),
            "resolution": list(self.spec.camera.resolution),
            "light_maps": self.spec.outputs.light_maps,
            "previews": self.spec.outputs.previews,
            "item_digits": L.ITEM_DIGITS,
            "shard": L.SHARD,
        }
        spec_path = os.path.join(self.root, SPEC)
        write_new(spec_path + ".tmp", self.spec.text.encode())
        os.replace(spec_path + ".tmp", spec_path)
        write_json_atomic(path, info)

    def _manifest_ends_cleanly(self, path: str) -> bool:
        fd = open_nofollow(path, os.O_RDONLY)
        try:
            size = os.fstat(fd).st_size
            return size == 0 or os.pread(fd, 1, size - 1) == b"\n"
        finally:
            os.close(fd)

    def append(self, record: dict[str, Any]) -> None:
        """Appends one record and fsyncs it (one write call: whole lines)."""
        line = json.dumps(record, sort_keys=True, separators=(",", ":")) + "\n"
        if not self._ends_with_newline:
            line = "\n" + line
        try:
            written = os.write(self._manifest_fd, line.encode())
            os.fsync(self._manifest_fd)
        except OSError as e:
            raise StorageError(f"out: cannot append to {MANIFEST} in {self.root!r}: {_describe(e)}. {_RESUME}") from e
        # A short write (a full disk) leaves a line cut short, which readers skip.
        self._ends_with_newline = written == len(line.encode())
        if not self._ends_with_newline:
            raise StorageError(
                f"out: {MANIFEST} in {self.root!r} took {written} of {len(line)} bytes (disk full?). {_RESUME}"
            )

    def close(self) -> None:
        for name in ("_manifest_fd", "_lock_fd"):
            fd = getattr(self, name, None)
            if fd is not None:
                os.close(fd)
                setattr(self, name, None)

    def __enter__(self) -> Output:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
