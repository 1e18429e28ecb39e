#!/usr/bin/env bash
# How the browser viewer copes with a big map (issue 17: >= 50k points and >= 500 keyframes load
# in < 2 s; orbiting frame rate), in headless Chromium with software rendering (SwiftShader).
#
#   bench/viewer_load.sh [--tiles N] [--seconds S] OUT
#
# No sequence plslam renders or reads here makes such a map in one run in reasonable time, so
# the run of the office loop (480 frames, seed 1: about 110 keyframes and 11k points) is laid
# out N x N times side by side (default 3: about 1000 keyframes and 100k points). Each copy is
# the same map shifted, with its own ids, so the page loads, draws and orbits N^2 times the data
# of one run. The trajectory and ground truth stay those of the one run.
# Prints the page's summary line: load ms (first byte requested to first frame drawn), pixel
# std, toggles checked, and the orbit frame rate over S seconds (default 5).
set -euo pipefail
cd "$(dirname "$0")/.."
tiles=3
seconds=5
while [ $# -gt 1 ]; do
  case "$1" in
    --tiles) tiles=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    *) echo "viewer_load.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/viewer_load.sh [--tiles N] [--seconds S] OUT}
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "viewer_load.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
[ -d "$out/office/mav0" ] || "$plslam" synth --scene office --frames 480 --loop --seed 1 --out "$out/office" >/dev/null 2>&1
[ -f "$out/run/stats.json" ] || "$plslam" run "$out/office" --out "$out/run" --quiet >/dev/null 2>&1

rm -rf "$out/big"
mkdir -p "$out/big"
python3 - "$out/run" "$out/big" "$tiles" <<'PY'
import json, shutil, sys
src, dst, n = sys.argv[1], sys.argv[2], int(sys.argv[3])

def read_vertices(path):
    lines = open(path).read().split("\n")
    end = lines.index("end_header")
    count = next(int(l.split()[2]) for l in lines[:end] if l.startswith("element vertex"))
    return [tuple(map(float, l.split())) for l in lines[end + 1:end + 1 + count]]

points = read_vertices(f"{src}/map_points.ply")
line_ends = read_vertices(f"{src}/map_lines.ply")
graph = json.load(open(f"{src}/map_graph.json"))
xs = [p[0] for p in points]
zs = [p[2] for p in points]  # x and z: the ground plane of the first camera's frame (y is down)
step_x = (max(xs) - min(xs)) * 1.1
step_z = (max(zs) - min(zs)) * 1.1
id_step = 1 + max(k["id"] for k in graph["keyframes"])

all_points, all_lines, keyframes = [], [], []
for i in range(n):
    for j in range(n):
        dx, dz, t = i * step_x, j * step_z, i * n + j
        all_points += [(x + dx, y, z + dz) for x, y, z in points]
        all_lines += [(x + dx, y, z + dz) for x, y, z in line_ends]
        off = t * id_step
        for k in graph["keyframes"]:
            T = list(k["T_wc"])
            T[3] += dx
            T[11] += dz
            keyframes.append({"id": k["id"] + off, "t": k["t"] + 1000.0 * t, "T_wc": T,
                              "parent": k["parent"] + off if k["parent"] >= 0 else -1,
                              "loop_edges": [e + off for e in k["loop_edges"]],
                              "covisibility": [[c + off, w] for c, w in k["covisibility"]]})

with open(f"{dst}/map_points.ply", "w") as f:
    f.write(f"ply\nformat ascii 1.0\nelement vertex {len(all_points)}\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n")
    f.writelines(f"{x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in all_points)
with open(f"{dst}/map_lines.ply", "w") as f:
    f.write(f"ply\nformat ascii 1.0\nelement vertex {len(all_lines)}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element edge {len(all_lines) // 2}\nproperty int vertex1\nproperty int vertex2\nend_header\n")
    f.writelines(f"{x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in all_lines)
    f.writelines(f"{2 * e} {2 * e + 1}\n" for e in range(len(all_lines) // 2))
json.dump({"version": 1, "keyframes": keyframes}, open(f"{dst}/map_graph.json", "w"))
shutil.copy(f"{src}/trajectory.tum", f"{dst}/trajectory.tum")
stats = json.load(open(f"{src}/stats.json"))
stats.update(keyframes=len(keyframes), map_points=len(all_points), map_lines=len(all_lines) // 2)
json.dump(stats, open(f"{dst}/stats.json", "w"))
json.dump({"keyframes": len(keyframes), "points": len(all_points), "lines": len(all_lines) // 2,
           "loops": len(stats["loops"]), "relocalizations": stats["relocalizations"]["count"]},
          open(f"{dst}/expect.json", "w"))
print(f"viewer_load.sh: {n}x{n} copies: {len(keyframes)} keyframes, {len(all_points)} points, "
      f"{len(all_lines) // 2} lines")
PY
node tests/web/viewer_page.mjs --cli "$plslam" --view "$out/big" --expect-json "$out/big/expect.json" \
  --out "$out" --name big --measure-fps "$seconds"
