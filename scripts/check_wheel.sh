#!/usr/bin/env bash
# Installs softshadow as a user does, from the abi3 manylinux wheel that
# setup.sh built (dist/wheels/), into a fresh virtual environment with no Rust
# toolchain on PATH, and runs the README's usage example there, outside the
# source tree (so that `import softshadow` cannot find python/softshadow).
#   scripts/check_wheel.sh
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
shopt -s nullglob
wheels=(dist/wheels/softshadow-*.whl)
[ ${#wheels[@]} -eq 1 ] || { echo "check_wheel.sh: expected one wheel in dist/wheels, found ${#wheels[@]} (run scripts/setup.sh)" >&2; exit 1; }
wheel="$root/${wheels[0]}"
case "$(basename "$wheel")" in
    *-abi3-manylinux*) ;;
    *) echo "check_wheel.sh: $(basename "$wheel") is not an abi3 manylinux wheel" >&2; exit 1 ;;
esac
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 -m venv "$work/venv"
# PATH with the system's tools only: no cargo, no rustc, no maturin.
export PATH="$work/venv/bin:/usr/local/bin:/usr/bin:/bin"
if command -v cargo >/dev/null || command -v rustc >/dev/null; then
    echo "check_wheel.sh: a Rust toolchain is on PATH ($(command -v cargo rustc))" >&2
    exit 1
fi
python -m pip install -q --upgrade pip
# --only-binary: pip must not fall back to building anything from source.
python -m pip install -q --only-binary=:all: "$wheel" "trimesh>=4"
python - "$root/README.md" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
block = re.search(r"```python\n(import numpy as np, trimesh, softshadow as ss.*?)```", text, re.S)
assert block, "the usage example is missing from the README"
import softshadow
assert "site-packages" in softshadow.__file__, softshadow.__file__
exec(compile(block.group(1), "README.md", "exec"), {})
print(f"check_wheel.sh: the README example ran from {softshadow.__file__}")
PY
