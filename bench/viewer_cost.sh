#!/usr/bin/env bash
# What the live viewer costs tracking (issue 17): the same sequence run N times each way,
# alternating, in the default (deterministic) mode, and the median of each run's median tracking ms.
#
#   bench/viewer_cost.sh [--runs N] [--dataset DIR] [--modes "off browser ..."] OUT
#
#   off      plslam run without --viewer
#   poller   --viewer at 5 Hz with a client that follows it as the page does (deltas every 200 ms,
#            the camera image when it changes): the server's side, as with a browser on another
#            machine
#   browser  --viewer at 5 Hz, the page opened in headless Chromium on this same machine once the
#            run prints its URL: the browser's launch, page load and software rendering
#            (SwiftShader) share the two cores with the run
#   niced    as browser, with Chromium at the lowest nice level (19). On these machines' kernel
#            (EEVDF) nice 19 still takes a large share: two nice-19 busy loops slow a nice-0 one by
#            28 %
#   idle     as browser, with Chromium in the SCHED_IDLE class (`chrt --idle 0`): it runs only on a
#            core that SLAM leaves free, and a woken SLAM thread preempts it at once
#   open     as browser, but Chromium is launched and waiting before the run starts (a page left
#            open on the robot's own screen): the steady cost of the page's updates and renders
# Default dataset: the office loop (480 frames, seed 1), rendered into OUT/office when missing.
# OUT/summary.txt has one line per mode: the runs' medians and the ratio of medians to `off`; the
# median (min-max) of each run's ratio to the `off` run of its own round; and for the browser
# modes the median CPU seconds Chromium used from opening the page to the run's final state, in
# all and by process type (browser, renderer, gpu-process, utility).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=5
dataset=""
modes="off poller browser niced idle open"
while [ $# -gt 1 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --dataset) dataset=$2; shift 2 ;;
    --modes) modes=$2; shift 2 ;;
    *) echo "viewer_cost.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/viewer_cost.sh [--runs N] [--dataset DIR] [--modes LIST] OUT}
case " $modes " in *" off "*) ;; *) echo "viewer_cost.sh: --modes must include off (the baseline)" >&2; exit 2 ;; esac
for m in $modes; do
  case "$m" in off|poller|browser|niced|idle|open) ;; *) echo "viewer_cost.sh: unknown mode $m" >&2; exit 2 ;; esac
done
plslam=${PLSLAM:-build/plslam}
[ -x "$plslam" ] || { echo "viewer_cost.sh: $plslam not built" >&2; exit 2; }
mkdir -p "$out"
if [ -z "$dataset" ]; then
  dataset="$out/office"
  [ -d "$dataset/mav0" ] || "$plslam" synth --scene office --frames 480 --loop --seed 1 --out "$dataset" >/dev/null 2>&1
fi

# Follows the live viewer until its final revision, as web/scene_client.js does.
poller() {
  python3 - "$1" <<'PY'
import json, sys, time, urllib.request
url = sys.argv[1]
revision, final = None, False
while not final:
    q = url + "api/scene" + ("" if revision is None else f"?since={revision}")
    try:
        with urllib.request.urlopen(q, timeout=10) as r:
            if r.status == 200:
                d = json.loads(r.read())
                final = d["deltas"][-1]["final"] if d.get("type") == "delta" else d["final"]
                revision = d["revision"]
                if not final:
                    urllib.request.urlopen(url + "api/image.jpg", timeout=10).read()
    except urllib.error.HTTPError:
        pass  # 404 for the image before the first frame
    time.sleep(0.2)
PY
}

browser() {
  node bench/viewer_follow.mjs "$1"
}

niced() {
  nice -n 19 node bench/viewer_follow.mjs "$1"
}

idle() {
  chrt --idle 0 node bench/viewer_follow.mjs "$1"
}

free_port() {
  python3 -c "import socket; s = socket.socket(); s.bind(('127.0.0.1', 0)); print(s.getsockname()[1])"
}

run_one() {  # mode, index
  local mode=$1 i=$2 dir="$out/$1-$2"
  rm -rf "$dir"
  if [ "$mode" = off ]; then
    "$plslam" run "$dataset" --out "$dir" --quiet >/dev/null 2>&1
  elif [ "$mode" = open ]; then
    local port
    port=$(free_port)
    node bench/viewer_follow.mjs "http://127.0.0.1:$port/" --before >"$dir.browser" 2>&1 &
    local browser_pid=$!
    for _ in $(seq 300); do
      grep -q "browser ready" "$dir.browser" 2>/dev/null && break
      sleep 0.1
    done
    "$plslam" run "$dataset" --out "$dir" --quiet --viewer --port "$port" --viewer-linger 5 >/dev/null 2>&1 &
    local pid=$!
    wait "$browser_pid" || true
    kill -TERM "$pid" 2>/dev/null || true
    wait "$pid" || true
  else
    "$plslam" run "$dataset" --out "$dir" --quiet --viewer --port 0 --viewer-linger 5 >"$dir.stdout" 2>/dev/null &
    local pid=$! url=""
    for _ in $(seq 100); do
      url=$(grep -o 'http://[0-9.]*:[0-9]*/' "$dir.stdout" 2>/dev/null || true)
      [ -n "$url" ] && break
      sleep 0.1
    done
    "$mode" "$url" >"$dir.browser" 2>&1
    kill -TERM "$pid" 2>/dev/null || true
    wait "$pid" || true
  fi
  python3 -c "import json; print(json.load(open('$dir/stats.json'))['tracking_ms']['median'])" >> "$out/$mode.txt"
  # Chromium's CPU seconds from the page's opening to the run's final state (the browser modes)
  sed -n 's/.*, \([0-9.]*\) s since the page was opened/\1/p' "$dir.browser" 2>/dev/null >> "$out/$mode.cpu" || true
  sed -n 's/^since the page was opened, by process: //p' "$dir.browser" 2>/dev/null >> "$out/$mode.split" || true
}

rm -f "$out"/{off,poller,browser,niced,idle,open}.{txt,cpu,split}
for i in $(seq "$runs"); do
  for mode in $modes; do
    run_one "$mode" "$i"
    echo "run $i $mode: $(tail -1 "$out/$mode.txt") ms"
  done
done
python3 - "$out" $modes <<'PY' | tee "$out/summary.txt"
import os, statistics, sys
out = sys.argv[1]
modes = sys.argv[2:]
runs = {m: [float(x) for x in open(f"{out}/{m}.txt")] for m in modes}
for m in modes:
    med = statistics.median(runs[m])
    # Each run against the `off` run of its own round: drift between rounds cancels.
    paired = sorted(a / b for a, b in zip(runs[m], runs["off"]))
    cpu = [float(x) for x in open(f"{out}/{m}.cpu")] if os.path.exists(f"{out}/{m}.cpu") else []
    cpu = f", Chromium CPU from page open {statistics.median(cpu):.2f} s" if cpu else ""
    if cpu and os.path.exists(f"{out}/{m}.split"):  # lines of "renderer 1.23 s, gpu-process 0.80 s, ..."
        parts = {}
        for line in open(f"{out}/{m}.split"):
            for item in line.strip().split(", "):
                name, seconds, _ = item.split(" ")
                parts.setdefault(name, []).append(float(seconds))
        cpu += " (" + ", ".join(f"{k} {statistics.median(v):.2f}" for k, v in sorted(parts.items())) + ")"
    listed = " ".join(f"{x:.1f}" for x in runs[m])
    print(f"{m:8s} median {med:.2f} ms/frame (runs: {listed}), ratio to off {med / statistics.median(runs['off']):.3f}, "
          f"per round {statistics.median(paired):.3f} ({paired[0]:.3f}-{paired[-1]:.3f}){cpu}")
PY
