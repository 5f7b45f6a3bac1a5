"""Writes tests/golden/hashes.json: a SHA-256 of the visibility (and, for the
mesh pipeline, of every light-view map) of each golden case, per backend.

Run once before a refactor that must not change results, commit the file,
and `test_golden.py` asserts the same bits after it:

    .venv/bin/python tests/golden/make_golden.py

The cases use the string forms of the API (`method="bitmask", samples=64`),
which every version keeps, so hashes made by one version check the next.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from cases import GPU_ADAPTER_KEY, all_hashes  # noqa: E402

import softshadow as ss  # noqa: E402

OUT = Path(__file__).resolve().parent / "hashes.json"


def main() -> None:
    backends = ["cpu"]
    adapter = None
    if ss.gpu_available():
        backends.append("gpu")
        adapter = GPU_ADAPTER_KEY()
    data = {"gpu_adapter": adapter, "hashes": all_hashes(backends)}
    OUT.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    print(f"{OUT}: {len(data['hashes'])} hashes ({', '.join(backends)}; GPU adapter {adapter})")


if __name__ == "__main__":
    main()
