#!/usr/bin/env bash
# Visual-inertial initialisation on renders (issue 52): for each motion profile and seed, the
# office at EuRoC's rate with EuRoC's IMU noise and non-zero biases, run by `plslam run`, whose
# stats.json "imu" holds the initialisation (or the last refused attempt). Compared with the truth:
# gravity in the first camera's frame (the run's world) from synth/left_camera.tum, and the gyro
# bias at the initialisation's time from state_groundtruth_estimate0. Once accepted, the run's
# world turns to the gravity-aligned one: the worst tilt error of trajectory.tum's poses against
# the truth's (z up) says how level every output is.
#
#   bench/imu_init.sh [--plslam PATH] [--seeds "1 2 3 4 5"] [--motions "walk handheld drone"]
#                     [--frames N] OUT
#
# OUT/imu_init.txt: one line per run. Renders of 4 s (80 frames); about 8 s per run.
set -euo pipefail
cd "$(dirname "$0")/.."
plslam=build/plslam seeds="1 2 3 4 5" motions="walk handheld drone" frames=80
while [ $# -gt 1 ]; do
  case "$1" in
    --plslam) plslam=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --motions) motions=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    *) echo "imu_init.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
out=${1:?usage: bench/imu_init.sh [--plslam PATH] [--seeds LIST] [--motions LIST] [--frames N] OUT}
plslam=$(realpath "$plslam")
mkdir -p "$out"
table="$out/imu_init.txt"
: > "$table"
for motion in $motions; do
  for seed in $seeds; do
    seq="$out/office_${motion}_$seed"
    [ -f "$seq/mav0/synth/synth.json" ] ||
      "$plslam" synth --out "$seq" --force --scene office --preset euroc --frames "$frames" --seed "$seed" \
        --motion "$motion" --imu-noise euroc > /dev/null 2>&1
    "$plslam" run "$seq" --out "$out/run_${motion}_$seed" > /dev/null 2>&1
    /usr/bin/python3 - "$seq" "$out/run_${motion}_$seed/stats.json" "$motion" "$seed" >> "$table" <<'PY'
import json, sys, math
import numpy as np
seq, stats, motion, seed = sys.argv[1:5]
imu = json.load(open(stats))["imu"]
init = imu.get("initialisation") or imu.get("last_attempt")
def q2R(x, y, z, w):
    return np.array([[1-2*(y*y+z*z), 2*(x*y-z*w), 2*(x*z+y*w)], [2*(x*y+z*w), 1-2*(x*x+z*z), 2*(y*z-x*w)],
                     [2*(x*z-y*w), 2*(y*z+x*w), 1-2*(x*x+y*y)]])
first = np.loadtxt(seq + "/mav0/synth/left_camera.tum")[0]
g_true = q2R(*first[4:8]).T @ np.array([0, 0, -1.0])  # the run's world is the first camera's frame
if init is None or "gyro_bias" not in init:
    print(f"{motion:8s} seed {seed}: no estimate ({init and init['reason']})")
    sys.exit()
g = np.array(init["gravity_direction_world"])
g_err = math.degrees(math.atan2(np.linalg.norm(np.cross(g, g_true)), g @ g_true))
gt = np.loadtxt(seq + "/mav0/state_groundtruth_estimate0/data.csv", delimiter=",", comments="#")
t = init.get("at_time_s", gt[-1, 0] * 1e-9)
row = gt[np.argmin(abs(gt[:, 0] * 1e-9 - t))]
bg_true, ba_true = row[11:14], row[14:17]
bg_err = np.linalg.norm(np.array(init["gyro_bias"]) - bg_true)
ok_g = g_err <= 0.5
ok_bg = bg_err <= max(0.1 * np.linalg.norm(bg_true), 2e-4)
state = f"accepted after {init['seconds_of_motion']:.2f} s" if init["accepted"] else "refused: " + init["reason"]
print(f"{motion:8s} seed {seed}: {state}; gravity error {g_err:.3f} deg (sigma {init['gravity_sigma_deg']:.3f}) "
      f"{'ok' if ok_g else 'OVER'}; gyro bias error {bg_err:.2e} of {np.linalg.norm(bg_true):.2e} "
      f"{'ok' if ok_bg else 'OVER'}; acc bias {np.round(init['acc_bias'], 3).tolist()} (true {np.round(ba_true, 3).tolist()}); "
      f"rotation {init['rotation_deg']:.0f} deg", end="")
world = imu.get("world", {})
if world.get("gravity_aligned"):
    truth = {round(r[0], 3): q2R(*r[4:8]) for r in np.loadtxt(seq + "/mav0/synth/left_camera.tum")}
    worst = 0.0
    for r in np.loadtxt(stats.replace("stats.json", "trajectory.tum")):
        down, down_true = q2R(*r[4:8]).T @ [0, 0, -1.0], truth[round(r[0], 3)].T @ [0, 0, -1.0]
        worst = max(worst, math.degrees(math.atan2(np.linalg.norm(np.cross(down, down_true)), down @ down_true)))
    print(f"; world z up from frame {world['from_frame']}, trajectory tilt error <= {worst:.3f} deg", end="")
print()
PY
    tail -1 "$table"
  done
done
