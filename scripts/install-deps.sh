#!/usr/bin/env bash
# Installs every Debian 12 package plslam needs. Idempotent: packages that are
# already present are skipped, and `apt-get update` runs at most once per call.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  libopencv-dev libopencv-contrib-dev
  libeigen3-dev libceres-dev libtbb-dev
  libcli11-dev libspdlog-dev libfmt-dev libyaml-cpp-dev
  nlohmann-json3-dev libcpp-httplib-dev libdeflate-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy python3-pytest dpkg-dev
  chromium parallel
)
# Node.js and npm install the viewer's three.js (web/package-lock.json). A machine may have them
# from elsewhere (NodeSource's nodejs holds npm and conflicts with Debian's npm package): Debian's
# are added only when no npm is found.
if ! command -v npm >/dev/null 2>&1; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "install-deps: done"
fi

# The viewer's npm packages, exactly as web/package-lock.json pins them; skipped when that lock
# file has not changed since the last `npm ci` here (the stamp is its copy).
cd "$(dirname "$0")/../web"
if ! cmp -s package-lock.json node_modules/.plslam-installed-lock.json; then
  echo "install-deps: npm ci in web/"
  npm ci --no-audit --no-fund --loglevel=error >/dev/null
  cp package-lock.json node_modules/.plslam-installed-lock.json
fi
