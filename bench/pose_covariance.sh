#!/usr/bin/env bash
# Is the pose covariance consistent (issue 51)? For the rendered office loops (seeds 1-3, EuRoC
# preset) and street loops (seeds 1-2, KITTI preset), and the real excerpts under ../shared/data
# when they are there, one sequential run each and the mean NEES of its frame-to-frame motions
# against the ground truth (stats.json accuracy.motion_nees; 6, the degrees of freedom, when the
# covariance is consistent), with the scale factor that would make it 6.
#
#   bench/pose_covariance.sh [--plslam PATH] OUT
#
# OUT/summary.txt: one line per sequence. About 6 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    *) echo "pose_covariance.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/pose_covariance.sh [--plslam PATH] OUT}
plslam=$(realpath "$plslam")
mkdir -p "$out"/{seq,runs}
out=$(realpath "$out")
: > "$out/summary.txt"

one() {
  local name=$1 seq=$2
  "$plslam" run "$seq" --out "$out/runs/$name" --quiet --sequential > "$out/runs/$name.log" 2>&1
  python3 - "$name" "$out/runs/$name/stats.json" <<'PY' | tee -a "$out/summary.txt"
import json, sys
name, a = sys.argv[1], json.load(open(sys.argv[2]))["accuracy"]
n = a["motion_nees"]
print(f"{name:<12} ATE {a['ape_trans_m']['rmse']:.4f} m  motions {n['motions']:>4}  NEES mean {n['mean']:6.2f}  "
      f"median {n['median']:6.2f}  ({n['mean'] / n['dof']:.2f}x the {n['dof']} dof; covariance x{n['mean'] / n['dof']:.2f} "
      f"would make it consistent)")
PY
}

for s in 1 2 3; do
  [ -d "$out/seq/office$s" ] || "$plslam" synth --out "$out/seq/office$s" --scene office --preset euroc --frames 480 \
    --loop --seed $s --force > /dev/null 2>&1
  one "office$s" "$out/seq/office$s"
done
for s in 1 2; do
  [ -d "$out/seq/street$s" ] || "$plslam" synth --out "$out/seq/street$s" --scene street --preset kitti --format kitti \
    --frames 600 --loop --seed $s --force > /dev/null 2>&1
  one "street$s" "$out/seq/street$s"
done
shared=../shared/data
if [ -d "$shared" ]; then
  for d in "$shared"/kitti/sequences/*/ "$shared"/euroc/*/; do
    [ -d "$d" ] || continue
    one "$(basename "$d")" "$d"
  done
fi
