#!/usr/bin/env bash
# Stereo-inertial against stereo-only (issue 53): the office loop rendered with each motion profile
# and seed, EuRoC's IMU noise and non-zero biases, run by `plslam run` with the IMU and with
# --no-imu (loop closing on). Per run: the ATE (se3), frames tracked, lost events, relocalizations,
# new map segments, frames tracked with the IMU and carried by it alone, and the ratio of the two
# ATEs. With --blackout S, frames S..S+19 (1 s) of both cameras are replaced by black images in a
# copy of each render, and the render without them is run with the IMU too: the line ends with
# the black-out's stereo-inertial ATE over that run's ("black-out ratio", the issue's bar).
#
#   bench/stereo_inertial.sh [--plslam PATH] [--seeds "31 32 33"] [--motions "handheld drone walk"]
#                            [--frames N] [--blackout S] OUT
#
# OUT/stereo_inertial.txt: one line per render. About 40 s per render and seed (two runs; three
# with --blackout).
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam seeds="31 32 33" motions="handheld drone walk" frames=480 blackout=-1
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --motions) motions=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --blackout) blackout=$2; shift 2 ;;
    *) echo "stereo_inertial.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/stereo_inertial.sh [--plslam PATH] [--seeds LIST] [--motions LIST] [--frames N] [--blackout S] OUT}
plslam=$(realpath "$plslam")
mkdir -p "$out"
out=$(realpath "$out")
table="$out/stereo_inertial.txt"
: > "$table"
# SEQ OUT: one run's figures from its stats.json.
figures() {
  /usr/bin/python3 - "$1/stats.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
imu = (s.get("imu") or {}).get("slam") or {}
ate = s.get("accuracy", {}).get("ape_trans_m", {}).get("rmse", float("nan"))
count = lambda v: v["count"] if isinstance(v, dict) else len(v) if isinstance(v, list) else v
print(f"{ate:.5f} tracked {s['tracked_frames']} lost {s['lost_events']} reloc {count(s['relocalizations'])} "
      f"segments {count(s['new_map_segments'])} imu {imu.get('imu_tracked_frames', 0)} inertial {imu.get('inertial_frames', 0)}")
PY
}
# A B: A / B, two decimals (ATEs as figures prints them first).
ratio() { /usr/bin/python3 -c "import sys; print(f'{float(sys.argv[1]) / float(sys.argv[2]):.2f}')" "$1" "$2"; }
for motion in $motions; do
  for seed in $seeds; do
    seq="$out/office_${motion}_$seed"
    [ -f "$seq/mav0/synth/synth.json" ] ||
      "$plslam" synth --out "$seq" --force --scene office --preset euroc --frames "$frames" --loop --seed "$seed" \
        --motion "$motion" --imu-noise euroc > /dev/null 2>&1
    input=$seq
    if [ "$blackout" -ge 0 ]; then
      input="$seq.blackout$blackout"
      rm -rf "$input"
      cp -rsH "$seq" "$input"  # -H: a render given as a symlink is copied, not written through
      python3 bench/lib/aliasing.py blackout "$input" "$blackout" 20
    fi
    "$plslam" run "$input" --out "$out/vi_${motion}_$seed" --quiet > /dev/null 2>&1 || true
    "$plslam" run "$input" --out "$out/vo_${motion}_$seed" --quiet --no-imu > /dev/null 2>&1 || true
    vi=$(figures "$out/vi_${motion}_$seed")
    vo=$(figures "$out/vo_${motion}_$seed")
    line="$motion seed $seed | stereo-inertial $vi | stereo $vo | ratio $(ratio "${vi%% *}" "${vo%% *}")"
    if [ "$blackout" -ge 0 ]; then
      "$plslam" run "$seq" --out "$out/vi_clean_${motion}_$seed" --quiet > /dev/null 2>&1 || true
      clean=$(figures "$out/vi_clean_${motion}_$seed")
      line="$line | without the black-out ${clean%% *} | black-out ratio $(ratio "${vi%% *}" "${clean%% *}")"
    fi
    echo "$line" | tee -a "$table"
  done
done
