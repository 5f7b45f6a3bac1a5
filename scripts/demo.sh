#!/usr/bin/env bash
# The main job: sets everything up, then computes the soft shadow map of the
# bunny floating over a floor, writes out/bunny_floating_visibility.{exr,png},
# and prints the timings and the error against a Mitsuba reference.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh reference,io
.venv/bin/python -m softshadow.experiments.demo --out out "$@"
