#!/usr/bin/env bash
# Drop-frame sensitivity (issue 20): the ATE of each real excerpt with every single frame removed
# in turn, against the ATE of the whole excerpt.
#
#   bench/drop_frame_sweep.sh [--plslam PATH] [--jobs J] [--datasets "k06 k01 euroc"] OUT
#
# A copy without frame k is written under OUT/work (images symlinked and renumbered; times,
# poses or the EuRoC data.csv lines of frame k removed; KITTI 01 has no times.txt, so 10 Hz times
# are written for every copy) and run with `plslam run --sequential`, which is deterministic, so
# J runs may share the machine without changing any result. OUT/sweep.txt gets "dataset frame ATE"
# (frame -1: nothing removed) and OUT/summary.txt the share of drops within 10 %, the median and
# the extremes per dataset. About 200 runs: 15-20 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam jobs=2 datasets="k06 k01 euroc"
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --datasets) datasets=$2; shift 2 ;;
    *) echo "drop_frame_sweep.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/drop_frame_sweep.sh [--plslam PATH] [--jobs J] [--datasets LIST] OUT}
shared=${PLSLAM_SHARED_DIR:-../shared}/data
plslam=$(realpath "$plslam")
mkdir -p "$out/work"
out=$(realpath "$out")

# one DATASET K: prints "DATASET K ATE" for the copy without frame K (-1: the whole excerpt).
one() {
  local ds=$1 k=$2 w="$out/work/$1-$2" target
  rm -rf "$w"
  mkdir -p "$w"
  case $ds in
    k06|k01)
      local id=${ds#k} src="$shared/kitti/sequences/${ds#k}" seq="$w/sequences/${ds#k}" n j=0 i f g
      mkdir -p "$seq/image_0" "$seq/image_1" "$w/poses"
      cp "$src/calib.txt" "$seq/"
      n=$(ls "$src/image_0" | wc -l)
      for ((i = 0; i < n; i++)); do
        [ "$i" -eq "$k" ] && continue
        f=$(printf "%06d.png" "$i"); g=$(printf "%06d.png" "$j")
        ln -s "$src/image_0/$f" "$seq/image_0/$g"; ln -s "$src/image_1/$f" "$seq/image_1/$g"
        if [ -f "$src/times.txt" ]; then sed -n "$((i + 1))p" "$src/times.txt"; else echo "$i" | awk '{printf "%e\n", $1 * 0.1}'; fi >> "$seq/times.txt"
        sed -n "$((i + 1))p" "$shared/kitti/poses/$id.txt" >> "$w/poses/$id.txt"
        j=$((j + 1))
      done
      target=$seq ;;
    euroc)
      local src="$shared/euroc/V1_01_easy_micro/mav0" m="$w/mav0" c
      mkdir -p "$m"
      ln -s "$src/state_groundtruth_estimate0" "$m/"
      for c in cam0 cam1; do
        mkdir -p "$m/$c"; ln -s "$src/$c/data" "$m/$c/data"; cp "$src/$c/sensor.yaml" "$m/$c/"
        awk -v k="$k" 'NR == 1 { print; next } NR - 2 != k { print }' "$src/$c/data.csv" > "$m/$c/data.csv"
      done
      target=$w ;;
    *) echo "drop_frame_sweep.sh: unknown dataset $ds (k06, k01 or euroc)" >&2; return 2 ;;
  esac
  local ate
  ate=$("$plslam" run "$target" --sequential --quiet --out "$w/out" 2>&1 | sed -nE 's/.*ATE \(se3\) rmse ([0-9.]+) m.*/\1/p')
  echo "$ds $k ${ate:-FAIL}"
  rm -rf "$w"
}
export -f one
export out shared plslam

: > "$out/sweep.txt"
for ds in $datasets; do
  case $ds in
    euroc) n=$(($(wc -l < "$shared/euroc/V1_01_easy_micro/mav0/cam0/data.csv") - 1)) ;;
    *) n=$(ls "$shared/kitti/sequences/${ds#k}/image_0" | wc -l) ;;
  esac
  for ((k = -1; k < n; k++)); do echo "$ds $k"; done
done | xargs -P "$jobs" -L1 bash -c 'one "$0" "$1"' | tee -a "$out/sweep.txt"

awk '
  { ate[$1, $2] = $3; if ($2 == -1) base[$1] = $3; else { n[$1]++; ks[$1, n[$1]] = $2 } }
  END {
    for (ds in n) {
      within = 0; lo = 1e9; hi = -1e9; fails = 0
      for (i = 1; i <= n[ds]; i++) {
        a = ate[ds, ks[ds, i]]
        if (a == "FAIL") { fails++; continue }
        c = (a / base[ds] - 1) * 100
        if (c <= 10 && c >= -10) within++
        if (c < lo) lo = c
        if (c > hi) hi = c
      }
      printf "%s: whole %s m, %d drops, %d within 10 %% (%.0f %%), change %+.1f %% .. %+.1f %%, %d failed\n", ds, base[ds], n[ds], within, 100 * within / n[ds], lo, hi, fails
    }
  }' "$out/sweep.txt" | tee "$out/summary.txt"
