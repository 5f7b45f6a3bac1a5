#!/usr/bin/env bash
# Sets everything up, then runs every test: the Rust core's (cargo test) and
# the package's (pytest, against Mitsuba references cached in .cache/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh test
export DRJIT_LIBLLVM_PATH="${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM-19.so}"
cargo fmt --all -- --check
.venv/bin/ruff check python tests benchmarks
cargo test --release --quiet
.venv/bin/python -m pytest -q "$@"
