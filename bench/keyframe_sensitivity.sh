#!/usr/bin/env bash
# How much an ATE moves when nothing but incidental choices change (issues 20 and 22).
#
#   bench/keyframe_sensitivity.sh [--office-seed S] [--kitti SEQ] OUT
#
# Every run here is `plslam run --sequential` (deterministic), so each difference comes from the
# change named on its line, never from thread scheduling:
#   - features.n_points moved by -4..+4 (0.3 % of the office's 1200, 0.2 % of KITTI's 2000);
#   - the keyframe policy's velocity_min_frames set to 1 and 3 on KITTI (which frames become
#     keyframes, with every frame still there);
#   - on the office loop, loop closing off (odometry), as in bench/odometry_analysis.sh.
# A dropped frame (bench/drop_frame_sweep.sh) and a free-running run (thread scheduling) change the
# same things: the feature sets and which frames become keyframes. OUT/summary.txt holds the ATE of
# each run and the median, min, max and max/min per group.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib/preset_key.sh
office_seed=1 kitti=${PLSLAM_SHARED_DIR:-../shared}/data/kitti/sequences/06
while [ $# -gt 1 ]; do
  case "$1" in
    --office-seed) office_seed=$2; shift 2 ;;
    --kitti) kitti=$2; shift 2 ;;
    *) echo "keyframe_sensitivity.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/keyframe_sensitivity.sh [--office-seed S] [--kitti SEQ] OUT}
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "keyframe_sensitivity.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out/configs" "$out/runs"
summary="$out/summary.txt"
: > "$summary"

# config PRESET SECTION KEY VALUE: the preset with SECTION.KEY set (replaced, or added under the
# section's header when the preset leaves it at its default); prints the file's path.
config() {
  local file="$out/configs/$1-$3-$4.yaml"
  preset_with_key "config/$1.yaml" "$2" "$3" "$4" "$file" || exit 2
  echo "$file"
}
# run GROUP LABEL DATASET CONFIG [ARGS...]: one deterministic run, one summary line.
run() {
  local group=$1 label=$2 dataset=$3 cfg=$4 dir="$out/runs/$1-$2"
  shift 4
  "$plslam" run "$dataset" --sequential --quiet --config "$cfg" --out "$dir" "$@" >/dev/null 2>&1
  python3 - "$dir/stats.json" "$group" "$label" <<'EOF' | tee -a "$summary"
import json, sys
s = json.load(open(sys.argv[1]))
print(f"{sys.argv[2]} {sys.argv[3]} ATE {s['accuracy']['ape_trans_m']['rmse']:.4f} keyframes {s['keyframes']}")
EOF
}

office="$out/office$office_seed"
[ -d "$office" ] || "$plslam" synth --out "$office" --scene office --preset euroc --frames 480 --loop \
  --seed "$office_seed" >/dev/null
for n in 1196 1197 1198 1199 1200 1201 1202 1203 1204; do
  run office-n_points "$n" "$office" "$(config euroc features n_points "$n")" --no-loop-closing
done
for n in 1996 1997 1998 1999 2000 2001 2002 2003 2004; do
  run kitti-n_points "$n" "$kitti" "$(config kitti features n_points "$n")"
done
for v in 1 2 3; do
  run kitti-velocity_min_frames "$v" "$kitti" "$(config kitti keyframe velocity_min_frames "$v")"
done

echo "--" | tee -a "$summary"
for group in office-n_points kitti-n_points kitti-velocity_min_frames; do
  grep "^$group " "$summary" | awk '{print $4}' | python3 -c '
import statistics as s, sys
v = sorted(float(x) for x in sys.stdin.read().split())
print("%s: median %.4f min %.4f max %.4f max/min %.2f (%d runs)" % (sys.argv[1], s.median(v), v[0], v[-1], v[-1] / v[0], len(v)))
' "$group" | tee -a "$summary"
done
