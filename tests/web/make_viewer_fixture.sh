#!/usr/bin/env bash
# The data the browser tests of the viewer look at (ctest fixture Viewer.Fixture):
#   DIR/office        a rendered office loop (460 frames, the shortest loop it renders; seed 4)
#   DIR/run           `plslam run` of it, with DIR/office.plmap saved at the end
#   DIR/expect_run.json, DIR/expect_map.json   the counts the page must show: from the run's
#                     stats.json, and from `plslam map info --json` of the map file
set -euo pipefail
cli=${1:?usage: make_viewer_fixture.sh PLSLAM_CLI DIR}
dir=${2:?usage: make_viewer_fixture.sh PLSLAM_CLI DIR}
rm -rf "$dir"
mkdir -p "$dir"
trap 'echo "make_viewer_fixture.sh failed; its log:" >&2; cat "$dir/log.txt" >&2' ERR
"$cli" synth --scene office --frames 460 --loop --seed 4 --out "$dir/office" >"$dir/log.txt" 2>&1
"$cli" run "$dir/office" --out "$dir/run" --save-map "$dir/office.plmap" --quiet >>"$dir/log.txt" 2>&1
python3 - "$dir" <<'PY'
import json, subprocess, sys
d = sys.argv[1]
stats = json.load(open(f"{d}/run/stats.json"))
json.dump({"keyframes": stats["keyframes"], "points": stats["map_points"], "lines": stats["map_lines"],
           "loops": len(stats["loops"]), "relocalizations": stats["relocalizations"]["count"]},
          open(f"{d}/expect_run.json", "w"))
PY
"$cli" map info "$dir/office.plmap" --json > "$dir/map_info.json"
python3 -c "
import json, sys
m = json.load(open('$dir/map_info.json'))
json.dump({'keyframes': m['keyframes'], 'points': m['points'], 'lines': m['lines']}, open('$dir/expect_map.json', 'w'))"
