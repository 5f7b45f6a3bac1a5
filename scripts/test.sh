#!/usr/bin/env bash
# Sets everything up, then runs every test: the Rust core's (cargo test) and
# the package's (pytest, against Mitsuba references cached in .cache/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh test
export DRJIT_LIBLLVM_PATH="${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM-19.so}"
# setup.sh installed lavapipe: GPU tests must find an adapter, not skip.
export SOFTSHADOW_REQUIRE_GPU="${SOFTSHADOW_REQUIRE_GPU:-1}"
cargo fmt --all -- --check
.venv/bin/ruff check python tests benchmarks
cargo test --release --quiet --features gpu
.venv/bin/python -m pytest -q "$@"
