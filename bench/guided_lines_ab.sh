#!/usr/bin/env bash
# Guided stereo lines against a second line detection in the right image (issue 19).
#
#   bench/guided_lines_ab.sh [--runs N] OUT
#
# lines.guided_stereo (on in both presets) finds each left line's right-image partner by a search
# along its rows; off, the right image gets its own line detection and LBD, matched as in the
# paper. This is bench/config_ab.sh with that key true and false: both alternate run by run, in the
# default (deterministic) mode with loop closing, on KITTI 06 and 01 (frames 0-50), the rendered street
# loop (300 frames, KITTI preset), the rendered office loop (480 frames) and the corridor loop (742
# frames; both EuRoC preset). OUT/summary.txt has each run's median tracking ms, ATE, keyframes and
# median stereo points and lines per frame, and per cell the medians and the ratio of tracking time
# to the guided (true) runs'.
# Timings are only comparable within one sitting: run nothing else meanwhile.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=3
while [ $# -gt 1 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    *) echo "guided_lines_ab.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/guided_lines_ab.sh [--runs N] OUT}
exec bench/config_ab.sh --key lines.guided_stereo --values "true false" --runs "$runs" "$out"
