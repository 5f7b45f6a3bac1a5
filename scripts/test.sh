#!/usr/bin/env bash
# Sets everything up, then runs every check and test: formatting, clippy on
# every feature combination that ships or is documented, a build without the
# GPU backend, rustdoc, the Rust core's tests (cargo test), ruff, the stubs
# against the compiled module (stubtest), a type check of the package (mypy),
# the package's tests (pytest, against Mitsuba references cached in .cache/),
# the quickstart notebook, and the wheel installed where there is no Rust.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh test
# setup.sh installed lavapipe: GPU tests must find an adapter, not skip.
export SOFTSHADOW_REQUIRE_GPU="${SOFTSHADOW_REQUIRE_GPU:-1}"
# pyo3's build script must find the interpreter the package is built for.
export PYO3_PYTHON="$PWD/.venv/bin/python"
cargo fmt --all -- --check
# The core alone, the GPU backend, the bindings, both (what maturin builds).
for features in "" gpu python python,gpu; do
    echo "clippy --features '$features'"
    cargo clippy --quiet --release --all-targets --no-default-features --features "$features" -- -D warnings
done
cargo build --quiet --release --no-default-features
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps --features gpu
cargo test --release --quiet --features gpu
.venv/bin/ruff check python tests benchmarks
.venv/bin/python -m mypy.stubtest softshadow._core
.venv/bin/python -m mypy
.venv/bin/python -m pytest -q "$@"
# The quickstart notebook, executed (nbmake); the repository keeps it stripped.
.venv/bin/python -m pytest -q --nbmake examples/quickstart.ipynb
# The wheel as a user without Rust installs it.
scripts/check_wheel.sh
