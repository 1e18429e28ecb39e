#!/usr/bin/env bash
# Black-out sweep (issue 14): the rendered office loop with 1 s of black frames at several places
# of the loop in turn, against the run without a black-out. What each run did after the black-out
# (tracked on, relocalized, or started a new map segment) and where it ended up.
#
#   bench/blackout_sweep.sh [--plslam PATH] [--starts "60 120 ..."] [--frames N] [--jobs J] OUT
#
# The office loop (480 frames, seed 1, 20 Hz) is rendered once into OUT/office. Each copy under
# OUT/work links the images and replaces frames START..START+19 of both cameras by black images.
# `plslam run --sequential` is deterministic, so J runs may share the machine without changing a
# result. OUT/sweep.txt: one line per run (start -1: no black-out) with the relocalized frames,
# the new map segments, the loops, the whole-run ATE (se3) and its ratio to the run without a
# black-out. A new segment is an honest answer when the camera comes back facing what the map has
# not seen; a relocalization far from the ground truth shows as a large ratio. About 8 runs of
# 15 s each.
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam jobs=2 starts="60 120 180 240 300 360 420" frames=480
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    --starts) starts=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    *) echo "blackout_sweep.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/blackout_sweep.sh [--plslam PATH] [--starts LIST] [--frames N] [--jobs J] OUT}
plslam=$(realpath "$plslam")
lib=$(realpath bench/lib/aliasing.py)
mkdir -p "$out/work"
out=$(realpath "$out")
office="$out/office"
[ -d "$office/mav0" ] || "$plslam" synth --scene office --preset euroc --frames "$frames" --loop --seed 1 \
  --out "$office" --force >/dev/null

# one START: the copy with frames START..START+19 black (-1: none), run, one line of results.
one() {
  local start=$1 w="$out/work/$1"
  rm -rf "$w" "$w.out"
  cp -rs "$office" "$w"
  if [ "$start" -ge 0 ]; then
    python3 "$lib" blackout "$w" "$start" 20
  fi
  "$plslam" run "$w" --out "$w.out" --sequential --quiet >/dev/null 2>&1 || true
  python3 - "$w.out/stats.json" "$start" <<'PY'
import json, sys
try:
    s = json.load(open(sys.argv[1]))
except (OSError, ValueError):
    print(f"{sys.argv[2]} failed"); sys.exit()
ate = s.get("accuracy", {}).get("ape_trans_m", {}).get("rmse")
print(sys.argv[2], "relocalized", s["relocalizations"]["frames"] or "-", "segments",
      s["new_map_segments"]["frames"] or "-", "loops", len(s["loops"]),
      "ate", f"{ate:.4f}" if ate is not None else "-")
PY
}
export -f one
export out office plslam lib
printf '%s\n' -1 $starts | xargs -P "$jobs" -I{} bash -c 'one {}' | sort -n > "$out/sweep.txt"
python3 - "$out/sweep.txt" <<'PY' | tee "$out/summary.txt"
import sys
rows = [l.split() for l in open(sys.argv[1])]
base = next((float(r[-1]) for r in rows if r[0] == "-1" and r[-1] != "-"), None)
for r in rows:
    ratio = f"{float(r[-1]) / base:.2f}x" if base and r[-1] not in ("-", "failed") else "-"
    print(" ".join(r), ratio)
PY
