#!/usr/bin/env bash
# Installs dependencies, builds, and runs the demo on the embedded default data.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
# The embedded synthetic sequence arrives with `plslam synth`; until then the demo inspects the
# real KITTI excerpt beside the repository when it is there.
if [ -d ../shared/data/kitti/sequences/06 ]; then
  "$BUILD_DIR/plslam" info ../shared/data/kitti/sequences/06
else
  "$BUILD_DIR/plslam" --help
fi
