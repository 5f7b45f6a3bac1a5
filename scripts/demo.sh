#!/usr/bin/env bash
# The main job: sets everything up, then renders the eye view of the bunny
# standing on a floor (shadowing itself) with softshadow beside Mitsuba 3's
# reference, writes the labelled figure out/demo.png and the EXRs
# out/bunny_on_floor.exr (every channel) and out/bunny_on_floor_reference.exr,
# and prints the timings and the error.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh reference,io,plot
.venv/bin/python -m softshadow.experiments.demo --out out "$@"
