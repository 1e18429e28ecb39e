#!/usr/bin/env bash
# Guided stereo lines against a second line detection in the right image (issue 19).
#
#   bench/guided_lines_ab.sh [--runs N] OUT
#
# lines.guided_stereo (on in both presets) finds each left line's right-image partner by a search
# along its rows; off, the right image gets its own line detection and LBD, matched as in the
# paper. This runs each preset with the key true and false, alternating run by run, in the default
# concurrent mode with loop closing, on KITTI 06 and 01 (frames 0-50), the rendered street loop
# (300 frames, KITTI preset), the rendered office loop (480 frames) and the corridor loop (742
# frames; both EuRoC preset). OUT/summary.txt has each run's median tracking ms, ATE, keyframes
# and median stereo lines per frame, and per cell the medians and the guided/detected ratio of
# tracking time.
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
plslam=${PLSLAM:-build/plslam}
shared=${PLSLAM_SHARED_DIR:-../shared}
[ -x "$plslam" ] || { echo "guided_lines_ab.sh: $plslam not built" >&2; exit 2; }
[ -d "$shared/data/kitti/sequences/06" ] || { echo "guided_lines_ab.sh: no KITTI excerpts under $shared/data" >&2; exit 2; }
mkdir -p "$out/configs" "$out/runs"
summary="$out/summary.txt"
: > "$summary"

for preset in kitti euroc; do
  for v in true false; do
    sed "s/^  guided_stereo: *true/  guided_stereo: $v/" "config/$preset.yaml" > "$out/configs/$preset-$v.yaml"
    grep -q "^  guided_stereo: $v" "$out/configs/$preset-$v.yaml" ||
      { echo "guided_lines_ab.sh: no lines.guided_stereo: true in config/$preset.yaml to replace" >&2; exit 2; }
  done
done

[ -d "$out/street" ] || "$plslam" synth --out "$out/street" --scene street --preset kitti --format kitti --frames 300 \
  --loop --seed 2 >/dev/null
[ -d "$out/office" ] || "$plslam" synth --out "$out/office" --scene office --preset euroc --frames 480 --loop --seed 1 >/dev/null
[ -d "$out/corridor" ] || "$plslam" synth --out "$out/corridor" --scene corridor --preset euroc --frames 742 --loop \
  --seed 2 >/dev/null

# cell NAME PRESET DATASET: N runs per value, alternating, one summary line each.
cell() {
  local name=$1 preset=$2 dataset=$3
  for i in $(seq "$runs"); do
    for v in true false; do
      local dir="$out/runs/$name-$v-$i"
      "$plslam" run "$dataset" --quiet --config "$out/configs/$preset-$v.yaml" --out "$dir" >/dev/null 2>&1 || true
      python3 - "$dir" "$name" "$v" "$i" <<'EOF' | tee -a "$summary"
import csv, json, statistics, sys
d, name, v, i = sys.argv[1:]
try:
    s = json.load(open(d + "/stats.json"))
    lines = statistics.median(int(r["stereo_lines"]) for r in csv.DictReader(open(d + "/frames.csv")))
    print(f"{name} guided {v} run {i} ms {s['tracking_ms']['median']:.2f} ATE {s['accuracy']['ape_trans_m']['rmse']:.4f} "
          f"keyframes {s['keyframes']} loops {len(s['loops'])} stereo_lines {lines:.0f}")
except (OSError, KeyError, ValueError) as e:
    print(f"{name} guided {v} run {i} failed {e}")
EOF
    done
  done
}

cell kitti06 kitti "$shared/data/kitti/sequences/06"
cell kitti01 kitti "$shared/data/kitti/sequences/01"
cell street kitti "$out/street"
cell office euroc "$out/office"
cell corridor euroc "$out/corridor"

python3 - "$summary" <<'EOF' | tee -a "$summary"
import collections, statistics, sys
cells = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) > 13 and f[1] == "guided" and f[5] == "ms":
        c = cells[(f[0], f[2])]
        c["ms"].append(float(f[6]))
        c["ate"].append(float(f[8]))
        c["lines"].append(float(f[14]))
print("sequence guided: median ms, median ATE m, median stereo lines; ratio of ms guided/detected")
for name in dict.fromkeys(k[0] for k in cells):
    row = []
    for v in ("true", "false"):
        c = cells.get((name, v))
        if c:
            row.append(f"{v}: {statistics.median(c['ms']):.2f} ms {statistics.median(c['ate']):.4f} m "
                       f"{statistics.median(c['lines']):.0f} lines")
    ratio = ""
    if (name, "true") in cells and (name, "false") in cells:
        ratio = f" ratio {statistics.median(cells[(name, 'true')]['ms']) / statistics.median(cells[(name, 'false')]['ms']):.2f}"
    print(f"{name} " + " | ".join(row) + ratio)
EOF
