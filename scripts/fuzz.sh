#!/usr/bin/env bash
# Fuzzes plslam's parsers of user input with libFuzzer (clang 14, ASan + UBSan), one target at a
# time, and prints each target's executions, edge coverage and findings.
#
#   scripts/fuzz.sh [--minutes N | --seconds S] [target...]   default: 5 minutes each, every target
#
# Targets (tests/fuzz/targets): config trajectory euroc_sensor euroc_data_csv euroc_groundtruth
# kitti_calib kitti_times frame_log image vocabulary bench_configs bench_plan published_results map_file calibration_file
# run_folder imu_csv imu_sensor. Each starts from tests/fuzz/corpus/<target>/ (the
# checked-in seeds) and keeps what it learns in build-fuzz/corpus/<target>/; crashes are written
# to build-fuzz/crashes/<target>/. A crash input belongs in tests/fuzz/corpus/<target>/ once the
# bug is fixed: the ctest FuzzReplay.* replays every corpus file in every build.
set -euo pipefail
cd "$(dirname "$0")/.."

minutes=5
seconds=""
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes="${2:?--minutes needs a number}"; shift 2 ;;
    --seconds) seconds="${2:?--seconds needs a number}"; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
seconds=${seconds:-$((minutes * 60))}
case "$seconds" in
  ''|*[!0-9]*|0) echo "fuzz.sh: the time per target must be a positive whole number of seconds" >&2; exit 2 ;;
esac
if [ ${#targets[@]} -eq 0 ]; then
  targets=(config trajectory euroc_sensor euroc_data_csv euroc_groundtruth kitti_calib kitti_times frame_log image vocabulary bench_configs bench_plan published_results map_file calibration_file run_folder imu_csv imu_sensor)
fi

BUILD_DIR=${BUILD_DIR:-build-fuzz}
cmake -S . -B "$BUILD_DIR" -DPLSLAM_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target $(printf 'fuzz_%s ' "${targets[@]}")

status=0
for t in "${targets[@]}"; do
  corpus="$BUILD_DIR/corpus/$t"
  crashes="$BUILD_DIR/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  log="$BUILD_DIR/fuzz_$t.log"
  echo "=== fuzz_$t for $seconds s"
  # Artifacts of earlier runs stay in $crashes for inspection; only this run's are counted.
  stamp="$BUILD_DIR/.fuzz_start_$t"
  touch "$stamp"
  rc=0
  "$BUILD_DIR/fuzz_$t" -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$crashes/" -print_final_stats=1 "$corpus" "tests/fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  execs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+)/\1/p' "$log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  found=$(find "$crashes" -type f -newer "$stamp" \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
  slow=$(find "$crashes" -type f -newer "$stamp" -name 'slow-unit-*' | wc -l)
  echo "fuzz_$t: exit $rc, ${execs:-?} executions, edge coverage ${cov:-?}, features ${ft:-?}, corpus $(ls "$corpus" | wc -l) files, crashes $found, slow inputs $slow (log $log)"
  if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then status=1; fi
done
exit $status
