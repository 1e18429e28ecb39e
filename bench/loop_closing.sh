#!/usr/bin/env bash
# Loop closing on rendered sequences with exact ground truth (issue 15).
#
#   bench/loop_closing.sh [--runs N] [--anchor PATH] [--sequences "office1 street2 office3 corridor street300"] OUT
#
# Renders each sequence once (office1: office loop seed 1, 480 frames; office3: seed 3; street2:
# street loop seed 2, 600 frames, kitti preset; corridor: 400 frames, no revisit; street300:
# street without loop, 300 frames). Runs plslam N times with loop closing and N times with
# --no-loop-closing, alternating, and with --anchor (../shared/anchors/orbslam3/run) the anchor
# with loop closing once per round. OUT/summary.txt: one line per run (ATE, loops as
# frame->matched frame, median tracking ms) and per sequence the median ATE of each and the ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=3 anchor="" sequences="office1 street2 office3 corridor street300"
while [ $# -gt 1 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --anchor) anchor=$2; shift 2 ;;
    --sequences) sequences=$2; shift 2 ;;
    *) echo "loop_closing.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/loop_closing.sh [options] OUT}
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "loop_closing.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out/runs"
summary="$out/summary.txt"
: > "$summary"

synth_args() {
  case "$1" in
    office1) echo "--scene office --preset euroc --frames 480 --loop --seed 1" ;;
    office3) echo "--scene office --preset euroc --frames 480 --loop --seed 3" ;;
    street2) echo "--scene street --preset kitti --frames 600 --loop --seed 2" ;;
    corridor) echo "--scene corridor --preset euroc --frames 400 --seed 1" ;;
    street300) echo "--scene street --preset kitti --frames 300 --seed 2" ;;
    *) echo "loop_closing.sh: unknown sequence $1" >&2; exit 2 ;;
  esac
}
ground_truth() {  # the camera trajectory synth wrote, whatever the layout
  find "$1" -name left_camera.tum | head -1
}
ate() {  # ATE RMSE (se3) of a TUM file against the sequence's ground truth
  "$plslam" eval --gt "$(ground_truth "$1")" --est "$2" --json 2>/dev/null |
    python3 -c 'import json,sys; print("%.4f" % json.load(sys.stdin)["ape_trans_m"]["rmse"])'
}
loops() {  # "frame->matched" per loop, from stats.json
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(" ".join("%d->%d" % (l["frame"], l["matched_frame"]) for l in d.get("loops", [])) or "-")' "$1"
}
median_ms() {
  python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("%.1f" % d["tracking_ms"]["median"])' "$1"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

for s in $sequences; do
  seq="$out/data/$s"
  [ -d "$seq" ] || "$plslam" synth $(synth_args "$s") --out "$seq" > /dev/null
  : > "$out/$s.lc"; : > "$out/$s.nolc"; : > "$out/$s.anchor"
  for r in $(seq 1 "$runs"); do
    for mode in lc nolc; do
      dir="$out/runs/$s-$mode-$r"
      extra=""; [ "$mode" = nolc ] && extra="--no-loop-closing"
      "$plslam" run "$seq" --out "$dir" --quiet $extra > "$dir.log" 2>&1 || echo "run failed: $dir" | tee -a "$summary"
      a=$(ate "$seq" "$dir/trajectory.tum")
      echo "$a" >> "$out/$s.$mode"
      echo "$s $mode run $r: ATE $a m, loops $(loops "$dir/stats.json"), tracking median $(median_ms "$dir/stats.json") ms" | tee -a "$summary"
    done
    if [ -n "$anchor" ]; then
      dir="$out/runs/$s-anchor-$r"
      "$anchor" "$seq" --out "$dir" --quiet > "$dir.log" 2>&1 || echo "anchor failed: $dir" | tee -a "$summary"
      a=$(ate "$seq" "$dir/trajectory.tum")
      echo "$a" >> "$out/$s.anchor"
      echo "$s anchor run $r: ATE $a m, loop corrections $(python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("loop_corrections"))' "$dir/stats.json")" | tee -a "$summary"
    fi
  done
  lc=$(median < "$out/$s.lc"); nolc=$(median < "$out/$s.nolc")
  line="$s: median ATE with loop closing $lc m, without $nolc m, ratio $(python3 -c "print('%.2f' % ($lc / $nolc))")"
  if [ -s "$out/$s.anchor" ]; then
    an=$(median < "$out/$s.anchor")
    line="$line; ORB-SLAM3 $an m (plslam / ORB-SLAM3 $(python3 -c "print('%.2f' % ($lc / $an))"))"
  fi
  echo "$line" | tee -a "$summary"
done
