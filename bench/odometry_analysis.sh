#!/usr/bin/env bash
# Odometry analysis on rendered office loops (issue 22): where the error grows and why.
#
#   bench/odometry_analysis.sh [--seeds "1 2 3"] [--runs N] [--anchor PATH] [--config FILE]
#                              [--free-running] OUT
#
# For each seed: renders `synth --scene office --preset euroc --frames 480 --loop --seed S`, runs
# plslam once with --sequential (reproducible) and once in the default mode, whose runs are
# identical (with --free-running: N times with --free-running; the anchor runs N times either way), all
# with --no-loop-closing (this measures the odometry: a closed loop would hide its drift), and,
# with --anchor (e.g. ../shared/anchors/orbslam3/run), the anchor with --no-loop-closing,
# alternating run by run with plslam. Every plslam run gets `plslam eval --plot --frames`:
# trajectory.png, ape.png, rpe.png and tracking.png (APE with keyframes, inliers against the
# keyframe threshold, local map size, close stereo points). OUT/summary.txt holds one line per
# run and the median, min and max ATE per seed and system.
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="1 2 3" runs=5 anchor="" config="" mode=deterministic
while [ $# -gt 1 ]; do
  case "$1" in
    --seeds) seeds=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --anchor) anchor=$2; shift 2 ;;
    --config) config="--config $2"; shift 2 ;;
    --deterministic) mode=deterministic; shift ;;  # the default
    --free-running) mode=free-running; shift ;;
    *) echo "odometry_analysis.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/odometry_analysis.sh [options] OUT}
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "odometry_analysis.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out"
summary="$out/summary.txt"
: > "$summary"

ate_of() {  # ATE RMSE of a TUM trajectory against the rendered ground truth
  "$plslam" eval --gt "$1/mav0/synth/left_camera.tum" --est "$2/trajectory.tum" --json 2>/dev/null |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["ape_trans_m"]["rmse"])'
}
stats() {  # median min max of numbers on stdin
  python3 -c 'import sys,statistics as s; v=sorted(float(x) for x in sys.stdin.read().split()); print("median %.4f min %.4f max %.4f max/min %.2f" % (s.median(v), v[0], v[-1], v[-1]/v[0]) if v else "none")'
}

for seed in $seeds; do
  seq="$out/office$seed"
  [ -d "$seq" ] || "$plslam" synth --out "$seq" --scene office --preset euroc --frames 480 --loop --seed "$seed" >/dev/null
  run_dir="$out/seed$seed-sequential"
  "$plslam" run "$seq" --sequential --no-loop-closing --quiet $config --out "$run_dir" >/dev/null
  "$plslam" eval --gt "$seq/mav0/synth/left_camera.tum" --est "$run_dir/trajectory.tum" --plot "$run_dir/plots" \
    --frames "$run_dir/frames.csv" >/dev/null 2>&1
  echo "seed $seed plslam-sequential ATE $(ate_of "$seq" "$run_dir")" | tee -a "$summary"
  for i in $(seq 1 "$runs"); do
    if [ -n "$anchor" ]; then
      a_dir="$out/seed$seed-anchor-$i"
      "$anchor" "$seq" --out "$a_dir" --no-loop-closing >/dev/null 2>&1
      echo "seed $seed anchor ATE $(ate_of "$seq" "$a_dir")" | tee -a "$summary"
    fi
    if [ "$mode" = deterministic ]; then
      [ "$i" -eq 1 ] || continue  # identical runs: one is the measurement
      run_dir="$out/seed$seed-deterministic"
      "$plslam" run "$seq" --no-loop-closing --quiet $config --out "$run_dir" >/dev/null
    else
      run_dir="$out/seed$seed-free-running-$i"
      "$plslam" run "$seq" --free-running --no-loop-closing --quiet $config --out "$run_dir" >/dev/null
    fi
    "$plslam" eval --gt "$seq/mav0/synth/left_camera.tum" --est "$run_dir/trajectory.tum" --plot "$run_dir/plots" \
      --frames "$run_dir/frames.csv" >/dev/null 2>&1
    echo "seed $seed plslam ATE $(ate_of "$seq" "$run_dir")" | tee -a "$summary"
  done
done
echo "--" | tee -a "$summary"
for seed in $seeds; do
  for sys in plslam anchor; do
    line=$(grep "^seed $seed $sys ATE" "$summary" | awk '{print $5}' | stats)
    [ "$line" = none ] || echo "seed $seed $sys: $line" | tee -a "$summary"
  done
done
# Over the seeds: the median of plslam's per-seed medians against the anchor's, and the seeds where
# plslam's median is worse than the anchor's median on it.
python3 - "$summary" <<'PY' | tee -a "$summary"
import re, statistics as st, sys
per = {}
for line in open(sys.argv[1]):
    m = re.match(r"seed (\d+) (plslam|anchor) ATE ([0-9.eE+-]+)$", line.strip())
    if m:
        per.setdefault(m[2], {}).setdefault(int(m[1]), []).append(float(m[3]))
if "anchor" in per and "plslam" in per:
    seeds = sorted(set(per["plslam"]) & set(per["anchor"]))
    p = {s: st.median(per["plslam"][s]) for s in seeds}
    a = {s: st.median(per["anchor"][s]) for s in seeds}
    mp, ma = st.median(p.values()), st.median(a.values())
    worse = [s for s in seeds if p[s] > a[s]]
    print(f"over {len(seeds)} seeds: plslam median {mp:.4f}, anchor median {ma:.4f}, ratio {mp / ma:.2f}; "
          f"seeds where plslam is worse than the anchor's median: {worse if worse else 'none'}")
PY
