#!/usr/bin/env bash
# A long run (issue 19): a rendered street loop driven again and again, N frames (default 6000:
# 10 minutes at 10 Hz, 12 laps of the 241 m loop at 5 m/s), run in the default (deterministic) mode.
#
#   bench/long_run.sh [--frames N] OUT
#
# OUT/run holds the run's outputs; OUT/plots/resources.png shows the tracking ms per frame (with
# its running median), the resident memory and the map's size over the frames, and
# OUT/summary.txt the numbers behind the claims: median tracking ms of the first and the last
# 1000 frames, resident memory at each lap's end, the map's growth per lap, what reclamation freed
# (stats.json `reclaimed`), and the ATE. The rendering takes most of the time (1240 s with one
# rendering thread on 2026-11-26; the run itself about 4 min); a sequence already rendered in
# OUT/street is reused.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=6000
while [ $# -gt 1 ]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    *) echo "long_run.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/long_run.sh [--frames N] OUT}
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "long_run.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out"
seq="$out/street"
if [ ! -f "$seq/sequences/00/times.txt" ] || [ "$(wc -l < "$seq/sequences/00/times.txt")" -ne "$frames" ]; then
  "$plslam" synth --out "$seq" --scene street --preset kitti --format kitti --frames "$frames" --loop \
    --loop-overlap 0 --seed 2 --force
fi
rm -rf "$out/run"
"$plslam" run "$seq/sequences/00" --out "$out/run" --quiet
"$plslam" eval --gt "$seq/poses/00.txt" --est "$out/run/trajectory.kitti" --plot "$out/plots" \
  --frames "$out/run/frames.csv" > "$out/eval.txt"
python3 - "$out" "$seq/sequences/00/synth/synth.json" > "$out/summary.txt" <<'PY'
import csv, json, statistics, sys
out, synth = sys.argv[1], json.load(open(sys.argv[2]))
rows = list(csv.DictReader(open(f"{out}/run/frames.csv")))
stats = json.load(open(f"{out}/run/stats.json"))
ms = [float(r["tracking_ms"]) for r in rows]
n = len(rows)
lap = round(synth["path_length_m"] / synth["speed_mps"] * synth["fps"])  # frames per lap
print(f"frames {n}, {lap} frames per lap ({synth['path_length_m']:.0f} m at {synth['speed_mps']:.1f} m/s)")
k = min(1000, n // 2)
first, last = statistics.median(ms[:k]), statistics.median(ms[-k:])
print(f"tracking ms median: first {k} frames {first:.1f}, last {k} frames {last:.1f} (last/first {last / first:.2f})")
print("lap  end frame  rss MiB  keyframes  points  lines  (growth of points, lines over the lap)")
prev = None
for i in range(lap - 1, n, lap):
    r = rows[i]
    cur = (int(r["map_keyframes"]), int(r["map_points"]), int(r["map_lines"]))
    grow = f"+{cur[1] - prev[1]}, +{cur[2] - prev[2]}" if prev else ""
    print(f"{i // lap + 1:3d}  {i:9d}  {float(r['rss_mb']):7.0f}  {cur[0]:9d}  {cur[1]:6d}  {cur[2]:5d}  {grow}")
    prev = cur
rss = [float(r["rss_mb"]) for r in rows]
print(f"rss MiB: at frame {k} {rss[k - 1]:.0f}, max {max(rss):.0f}, at the end {rss[-1]:.0f}")
rec = stats["reclaimed"]
print(f"reclaimed: {rec['points']} points, {rec['lines']} lines in {rec['runs']} runs "
      f"(median {rec['ms']['median']:.2f} ms, max {rec['ms']['max']:.2f} ms in tracking's thread); "
      f"culled keyframes {stats.get('culled_keyframes')}")
print(f"tracked {stats['tracked_frames']} of {stats['frames']}, lost events {stats['lost_events']}, "
      f"loops {len(stats.get('loops', []))}")
PY
grep -E "^APE" "$out/eval.txt" >> "$out/summary.txt" || true
cat "$out/summary.txt"
