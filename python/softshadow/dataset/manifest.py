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
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
from typing import Any

from . import limits as L
from .fields import SpecError
from .files import inside
from .spec import Spec

FORMAT = 1
SPEC = "spec.toml"
DATASET = "dataset.json"
MANIFEST = "manifest.jsonl"
LOCK = "lock"


class OutputError(RuntimeError):
    """``--out`` cannot be used: not writable, locked, or another spec's dataset."""


class StorageError(RuntimeError):
    """The output folder cannot take more files (full, read-only, forbidden)."""


def _describe(e: OSError) -> str:
    return f"{e.strerror or e} ({errno.errorcode.get(e.errno or 0, e.errno)})"


def write_json_atomic(path: str, value: Any) -> None:
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(value, f, indent=1, sort_keys=True)
        f.write("\n")
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_manifest(out: str) -> dict[int, dict[str, Any]]:
    """The last record of every item in the manifest (an empty dict if there is none)."""
    records: dict[int, dict[str, Any]] = {}
    try:
        with open(os.path.join(out, MANIFEST), encoding="utf-8", errors="replace") as f:
            for line in f:
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut short by a crash
                if isinstance(rec, dict) and isinstance(rec.get("k"), int) and rec.get("status") in ("done", "failed"):
                    records[rec["k"]] = rec
    except FileNotFoundError:
        pass
    return records


def read_dataset(out: str) -> dict[str, Any]:
    """``dataset.json`` of an output folder; OutputError if it is missing or unreadable."""
    path = os.path.join(out, DATASET)
    try:
        with open(path, encoding="utf-8") as f:
            info = json.load(f)
    except FileNotFoundError as e:
        raise OutputError(f"out: {out!r} holds no dataset ({DATASET} is missing)") from e
    except (OSError, json.JSONDecodeError) as e:
        raise OutputError(f"out: cannot read {path!r}: {e}") from e
    if not isinstance(info, dict) or info.get("format") != FORMAT:
        raise OutputError(f"out: {path!r} is not a softshadow dataset of format {FORMAT}")
    return info


class Output:
    """An output folder opened for a run: locked, the spec checked and stored."""

    def __init__(self, out: str, spec: Spec, count: int) -> None:
        self.root = os.path.abspath(out)
        self.spec = spec
        try:
            os.makedirs(self.root, exist_ok=True)
            self._lock_fd = os.open(os.path.join(self.root, LOCK), os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as e:
            raise OutputError(f"out: cannot create or write {self.root!r}: {_describe(e)}") from e
        try:
            fcntl.flock(self._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as e:
            os.close(self._lock_fd)
            raise OutputError(f"out: another run is writing into {self.root!r} (its {LOCK} is held)") from e
        try:
            self._claim(count)
            self._manifest_fd = os.open(
                os.path.join(self.root, MANIFEST), os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644
            )
        except OSError as e:
            self.close()
            raise OutputError(f"out: cannot write into {self.root!r}: {_describe(e)}") from e
        except BaseException:
            self.close()
            raise
        self._ends_with_newline = self._manifest_ends_cleanly()
        inside(self.root, spec.outputs.folder)  # the spec checked it; a link must not lead out either

    def _claim(self, count: int) -> None:
        spec_hash = self.spec.hash
        path = os.path.join(self.root, DATASET)
        if os.path.exists(path):
            info = read_dataset(self.root)
            if info.get("spec_hash") != spec_hash:
                raise SpecError(
                    f"spec: {self.root!r} holds items of another spec (hash {str(info.get('spec_hash'))[:12]}..., "
                    f"this one {spec_hash[:12]}...); use another --out"
                )
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
        tmp = spec_path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(self.spec.text)
        os.replace(tmp, spec_path)
        write_json_atomic(path, info)

    def _manifest_ends_cleanly(self) -> bool:
        path = os.path.join(self.root, MANIFEST)
        size = os.path.getsize(path)
        if size == 0:
            return True
        with open(path, "rb") as f:
            f.seek(size - 1)
            return f.read(1) == b"\n"

    def append(self, record: dict[str, Any]) -> None:
        """Appends one record and fsyncs it (one write call: whole lines)."""
        line = json.dumps(record, sort_keys=True, separators=(",", ":")) + "\n"
        if not self._ends_with_newline:
            line = "\n" + line
        try:
            written = os.write(self._manifest_fd, line.encode())
            os.fsync(self._manifest_fd)
        except OSError as e:
            raise StorageError(f"out: cannot append to {MANIFEST} in {self.root!r}: {_describe(e)}") from e
        # A short write (a full disk) leaves a line cut short, which readers skip.
        self._ends_with_newline = written == len(line.encode())
        if not self._ends_with_newline:
            raise StorageError(f"out: {MANIFEST} in {self.root!r} took {written} of {len(line)} bytes (disk full?)")

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
