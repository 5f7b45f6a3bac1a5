#!/usr/bin/env bash
# Installs everything softshadow needs on a fresh Debian machine (run as root):
# Debian's libLLVM 19 (Mitsuba's llvm variants need LLVM >= 16; Debian's 15
# crashes Dr.Jit), the Vulkan loader and Mesa's Vulkan drivers (lavapipe, a
# CPU Vulkan device, so that the GPU backend runs and is tested without a
# GPU), a virtual environment in .venv, and the package built from source
# (Rust, through maturin, as a wheel in dist/wheels) with the extras given as
# arguments.
#   scripts/setup.sh            -> the package only
#   scripts/setup.sh test       -> the package, Mitsuba, trimesh, OpenEXR, pytest
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
for pkg in libllvm19 libvulkan1 mesa-vulkan-drivers; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
fi
command -v cargo >/dev/null || { echo "setup.sh: cargo (Rust) is required" >&2; exit 1; }

[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip "maturin>=1.9,<2"
# The wheel a user installs: abi3 (one wheel for every CPython >= 3.10),
# tagged with the oldest manylinux its symbols allow (maturin audits it).
# scripts/check_wheel.sh installs this same file in a fresh environment.
rm -rf dist/wheels
.venv/bin/maturin build --quiet --release --out dist/wheels
wheel="$(ls dist/wheels/softshadow-*.whl)"
extras="${1:-}"
spec="$wheel"
[ -n "$extras" ] && spec="$wheel[$extras]"
.venv/bin/python -m pip install -q --force-reinstall --no-deps "$wheel"
.venv/bin/python -m pip install -q "$spec"
