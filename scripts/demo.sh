#!/usr/bin/env bash
# Installs dependencies, builds, renders the embedded default sequence (synthetic office with a
# loop, EuRoC layout, exact ground truth) into the build tree unless it is already there, and
# runs the demo on it. Nothing is downloaded beyond the Debian packages.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
# The `plslam` command only: the tests, benchmarks and Python module are not needed for the demo.
cmake --build "$BUILD_DIR" -j"$(nproc)" --target plslam

# 480 frames at 20 Hz walk the 31 m office loop once (at 1.35 m/s) and return to the start.
DATA="$BUILD_DIR/data/office_loop"
if [ ! -f "$DATA/mav0/synth/synth.json" ]; then  # synth.json is written last: complete data
  rm -rf "$DATA"
  "$BUILD_DIR/plslam" synth --out "$DATA" --scene office --preset euroc --frames 480 --loop --seed 1
fi
"$BUILD_DIR/plslam" info "$DATA"
# Stereo point-line SLAM on it: trajectory, map and statistics in build/demo_run, ATE/RPE at the end.
"$BUILD_DIR/plslam" run "$DATA" --out "$BUILD_DIR/demo_run"
