#!/usr/bin/env bash
# The aliasing battery (issue 51): where the rendered world repeats itself, no frame may be
# reported as tracked, relocalized or localized far from where the camera is.
#
#   bench/aliasing.sh [--plslam PATH] [--cases reverse,kidnap,blackout] OUT
#
# Cases, every run sequential (reproducible):
#   reverse   localization (--localize) on the reversed path through a map of the forward loop:
#             office seeds 1-3 (EuRoC preset), street seeds 1-2 (KITTI preset, 600 frames);
#   kidnap    the street loop and the corridor played to a frame, 20 black frames, then 61 frames
#             from a place 1, 2 and 3 repetitions of the scene (street 9 m, corridor 5.5 m) back
#             along the path, which the map has seen;
#   blackout  1 s of black frames at ten places of the office loop (seed 1) and the street loop
#             (seed 2).
# Rearranged copies link the rendered images (bench/lib/aliasing.py copy). For every run,
# OUT/summary.txt gives the frames in each state (frames.csv) and, for every frame with a trusted
# pose (trajectory.tum), its position error in the map's frame against the exact ground truth with
# no alignment: `wrong` counts those more than 0.3 m off. OUT/results.jsonl holds the same as
# JSON. Exits 1 when any case has a wrong frame. About 25 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam cases=reverse,kidnap,blackout
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    --cases) cases=$2; shift 2 ;;
    *) echo "aliasing.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/aliasing.sh [--plslam PATH] [--cases reverse,kidnap,blackout] OUT}
plslam=$(realpath "$plslam")
lib=$(realpath bench/lib/aliasing.py)
mkdir -p "$out"/{seq,maps,runs}
out=$(realpath "$out")
: > "$out/results.jsonl"
started=$(date +%s)

# render NAME SYNTH-ARGS...: a rendered sequence under OUT/seq, once.
render() {
  local name=$1
  shift
  [ -d "$out/seq/$name" ] || "$plslam" synth --out "$out/seq/$name" "$@" --force >/dev/null 2>&1
}

# record CASE MAP_SEQ RUN_SEQ RUN_DIR RC: scores one run into results.jsonl and summary.txt.
record() {
  local case=$1 map_seq=$2 run_seq=$3 dir=$4 rc=$5 json
  json=$(python3 "$lib" eval "$map_seq" "$run_seq" "$dir")
  echo "{\"case\": \"$case\", \"exit_code\": $rc, \"result\": $json}" >> "$out/results.jsonl"
  python3 - "$case" "$rc" "$json" "$started" <<'PY' | tee -a "$out/summary.txt"
import json, sys, time
case, rc, r, started = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), int(sys.argv[4])
states = ", ".join(f"{k} {v}" for k, v in sorted(r["states"].items()))
m = r["max_error_m"]
print(f"{case:<28} exit {rc}  {states:<58} trusted {r['trusted']:>4}  wrong {r['wrong']:>3}  "
      f"max {('%.3f m' % m) if m is not None else '-':>9}  [{int(time.time()) - started} s]")
PY
}

# run_case CASE MAP_SEQ RUN_SEQ RUN_DIR PLSLAM-RUN-ARGS...: one run (exit 0 or 3 are results).
run_case() {
  local case=$1 map_seq=$2 run_seq=$3 dir=$4 rc=0
  shift 4
  rm -rf "$dir"
  "$plslam" run "$run_seq" --out "$dir" --quiet --sequential "$@" > "$dir.log" 2>&1 || rc=$?
  if [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ]; then
    echo "aliasing.sh: $case: plslam run exited $rc (log: $dir.log)" >&2
    exit 1
  fi
  record "$case" "$map_seq" "$run_seq" "$dir" "$rc"
}

frames_of() { wc -l < "$(find "$out/seq/$1" -name left_camera.tum)"; }

if [[ ,$cases, == *,reverse,* ]]; then
  for s in 1 2 3 1k 2k; do
    if [[ $s == *k ]]; then
      seed=${s%k} name=street$seed args=(--scene street --preset kitti --format kitti --frames 600 --loop --seed $seed)
    else
      seed=$s name=office$seed args=(--scene office --preset euroc --frames 480 --loop --seed $seed)
    fi
    render "$name" "${args[@]}"
    render "$name-reverse" "${args[@]}" --path-seed 2
    map="$out/maps/$name.plmap"
    if [ ! -f "$map" ]; then
      "$plslam" run "$out/seq/$name" --out "$out/runs/map-$name" --quiet --sequential --save-map "$map" \
        > "$out/runs/map-$name.log" 2>&1
    fi
    run_case "reverse $name" "$out/seq/$name" "$out/seq/$name-reverse" "$out/runs/reverse-$name" \
      --load-map "$map" --localize
  done
fi

if [[ ,$cases, == *,kidnap,* ]]; then
  render street2 --scene street --preset kitti --format kitti --frames 600 --loop --seed 2
  render corridor --scene corridor --preset euroc --frames 600 --seed 1
  for scene in street2:9:400 corridor:5.5:500; do
    IFS=: read -r name period vanish <<< "$scene"
    for k in 1 2 3; do
      back=$(python3 "$lib" back "$out/seq/$name" "$vanish" "$(python3 -c "print($k * $period)")")
      copy="$out/seq/$name-kidnap$k"
      [ -d "$copy" ] || python3 "$lib" copy "$out/seq/$name" "$copy" "0-$vanish,B20,$back-$((back + 60))"
      run_case "kidnap $name ${k}x$period m" "$copy" "$copy" "$out/runs/kidnap-$name-$k"
    done
  done
fi

if [[ ,$cases, == *,blackout,* ]]; then
  render office1 --scene office --preset euroc --frames 480 --loop --seed 1
  render street2 --scene street --preset kitti --format kitti --frames 600 --loop --seed 2
  for name in office1 street2; do
    n=$(( $(frames_of "$name") - 1 ))
    for i in 0 1 2 3 4 5 6 7 8 9; do
      start=$(( 20 + i * (n - 60) / 9 ))
      copy="$out/seq/$name-blackout$start"
      [ -d "$copy" ] || python3 "$lib" copy "$out/seq/$name" "$copy" "0-$((start - 1)),B20,$((start + 20))-$((n - 1))"
      run_case "blackout $name @$start" "$copy" "$copy" "$out/runs/blackout-$name-$start"
    done
  done
fi

wrong=$(python3 -c "import json,sys; print(sum(json.loads(l)['result']['wrong'] for l in open(sys.argv[1])))" \
  "$out/results.jsonl")
echo "frames reported trusted more than 0.3 m from the truth, all cases: $wrong" | tee -a "$out/summary.txt"
[ "$wrong" -eq 0 ]
