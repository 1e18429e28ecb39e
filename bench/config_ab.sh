#!/usr/bin/env bash
# One configuration key, two or more values, side by side on the real excerpts and the renders.
#
#   bench/config_ab.sh --key SECTION.KEY --values "A B ..." [--runs N] [--sequences "..."] OUT
#
# Each preset gets SECTION.KEY set to each value (replaced, or added under the section's header).
# Every sequence then runs N times per value, the values alternating run by run, in the default
# mode (deterministic: its runs are identical, N=1 suffices) with loop closing: KITTI 06 and 01 (kitti preset), the rendered street loop (300
# frames, kitti preset), the rendered office loop (480 frames) and the corridor loop (742 frames;
# both euroc preset). Renders already in OUT/street, OUT/office and OUT/corridor (or symlinks
# there) are reused. OUT/summary.txt has each run's median tracking ms, ATE, keyframes and median
# stereo points and lines per frame, then per sequence and value the medians, the ATE range, and
# the ratio of tracking ms to the first value's. bench/guided_lines_ab.sh is this script for
# lines.guided_stereo.
# Timings are only comparable within one sitting: run nothing else meanwhile.
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/lib/preset_key.sh
runs=3 key="" values="" sequences="kitti06 kitti01 street office corridor"
while [ $# -gt 1 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --key) key=$2; shift 2 ;;
    --values) values=$2; shift 2 ;;
    --sequences) sequences=$2; shift 2 ;;
    *) echo "config_ab.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/config_ab.sh --key SECTION.KEY --values \"A B\" [--runs N] [--sequences \"...\"] OUT}
section=${key%%.*} name=${key#*.}
[ -n "$key" ] && [ "$section" != "$key" ] || { echo "config_ab.sh: --key must be SECTION.KEY" >&2; exit 2; }
[ -n "$values" ] || { echo "config_ab.sh: --values is empty" >&2; exit 2; }
plslam=${PLSLAM:-build/plslam}
shared=${PLSLAM_SHARED_DIR:-../shared}
[ -x "$plslam" ] || { echo "config_ab.sh: $plslam not built" >&2; exit 2; }
case " $sequences " in
  *" kitti06 "*|*" kitti01 "*)
    [ -d "$shared/data/kitti/sequences/06" ] || { echo "config_ab.sh: no KITTI excerpts under $shared/data" >&2; exit 2; } ;;
esac
mkdir -p "$out/configs" "$out/runs"
summary="$out/summary.txt"
: > "$summary"

for preset in kitti euroc; do
  for v in $values; do
    preset_with_key "config/$preset.yaml" "$section" "$name" "$v" "$out/configs/$preset-$v.yaml" || exit 2
  done
done

render() {
  local dir=$1; shift
  [ -e "$out/$dir" ] || "$plslam" synth --out "$out/$dir" "$@" >/dev/null
}

# cell NAME PRESET DATASET: N runs per value, alternating, one summary line each.
cell() {
  local name=$1 preset=$2 dataset=$3
  for i in $(seq "$runs"); do
    for v in $values; do
      local dir="$out/runs/$name-$v-$i"
      "$plslam" run "$dataset" --quiet --config "$out/configs/$preset-$v.yaml" --out "$dir" >"$dir.log" 2>&1 || true
      python3 - "$dir" "$name" "$v" "$i" <<'EOF' | tee -a "$summary"
import csv, json, statistics, sys
d, name, v, i = sys.argv[1:]
try:
    s = json.load(open(d + "/stats.json"))
    rows = list(csv.DictReader(open(d + "/frames.csv")))
    points = statistics.median(int(r["stereo_points"]) for r in rows)
    lines = statistics.median(int(r["stereo_lines"]) for r in rows)
    print(f"{name} value {v} run {i} ms {s['tracking_ms']['median']:.2f} ATE {s['accuracy']['ape_trans_m']['rmse']:.4f} "
          f"keyframes {s['keyframes']} tracked {s['tracked_frames']}/{s['frames']} stereo_points {points:.0f} "
          f"stereo_lines {lines:.0f}")
except (OSError, KeyError, ValueError) as e:
    print(f"{name} value {v} run {i} failed {e}")
EOF
    done
  done
}

for s in $sequences; do
  case "$s" in
    kitti06) cell kitti06 kitti "$shared/data/kitti/sequences/06" ;;
    kitti01) cell kitti01 kitti "$shared/data/kitti/sequences/01" ;;
    street)
      render street --scene street --preset kitti --format kitti --frames 300 --loop --seed 2
      cell street kitti "$out/street" ;;
    office)
      render office --scene office --preset euroc --frames 480 --loop --seed 1
      cell office euroc "$out/office" ;;
    corridor)
      render corridor --scene corridor --preset euroc --frames 742 --loop --seed 2
      cell corridor euroc "$out/corridor" ;;
    *) echo "config_ab.sh: unknown sequence $s" >&2; exit 2 ;;
  esac
done

python3 - "$summary" "$values" <<'EOF' | tee -a "$summary"
import collections, statistics, sys
values = sys.argv[2].split()
cells = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) > 15 and f[1] == "value" and f[5] == "ms":
        c = cells[(f[0], f[2])]
        c["ms"].append(float(f[6]))
        c["ate"].append(float(f[8]))
        c["kf"].append(float(f[10]))
        c["points"].append(float(f[14]))
        c["lines"].append(float(f[16]))
print(f"per sequence and value: median tracking ms (ratio to {values[0]}), median ATE m (min-max), median keyframes, "
      "median stereo points and lines")
for name in dict.fromkeys(k[0] for k in cells):
    base = cells.get((name, values[0]))
    for v in values:
        c = cells.get((name, v))
        if not c:
            continue
        ms = statistics.median(c["ms"])
        ratio = f" ({ms / statistics.median(base['ms']):.3f}x)" if base else ""
        print(f"{name} {v}: {ms:.2f} ms{ratio}, ATE {statistics.median(c['ate']):.4f} ({min(c['ate']):.4f}-{max(c['ate']):.4f}), "
              f"{statistics.median(c['kf']):.0f} keyframes, {statistics.median(c['points']):.0f} stereo points, "
              f"{statistics.median(c['lines']):.0f} stereo lines")
EOF
