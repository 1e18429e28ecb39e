#!/usr/bin/env bash
# Builds the Debian package: the library, headers, CMake package, `plslam` command, Python module,
# configs and vocabulary, for the /usr prefix. Writes $BUILD_DIR/plslam_<version>_<arch>.deb;
# install it with `sudo apt install ./build-deb/plslam_*.deb`.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-deb}
bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
  -DPLSLAM_BUILD_TESTS=OFF -DPLSLAM_BUILD_BENCH=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
(cd "$BUILD_DIR" && cpack -G DEB >/dev/null)
ls "$BUILD_DIR"/plslam_*.deb
