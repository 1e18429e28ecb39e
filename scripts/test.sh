#!/usr/bin/env bash
# Installs dependencies, builds and runs the test suite through ctest.
#
#   scripts/test.sh                              Release build in build/, the whole suite
#   scripts/test.sh --sanitize address,undefined ASan+UBSan build in build-asan/, the whole suite
#   scripts/test.sh --sanitize thread            TSan build in build-tsan/, the threaded tests
#   scripts/test.sh --sanitize thread --tests R  ... only the ctest tests whose name matches regex R
#     (ctest names: the tests of tests/test_lists.cmake one by one, every other suite as "Suite.*")
#
# Other arguments go to CMake (e.g. -DPLSLAM_SHARED_DIR=...). BUILD_DIR overrides the build folder.
# A sanitizer build is -O1 -g1 with frame pointers (cmake/Sanitizers.cmake) and every test process
# stops at its first report (halt_on_error), so any report fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."

sanitize=""
tests_regex=""
cmake_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sanitize) sanitize="${2:?--sanitize needs address,undefined or thread}"; shift 2 ;;
    --sanitize=*) sanitize="${1#*=}"; shift ;;
    --tests) tests_regex="${2:?--tests needs a regex}"; shift 2 ;;
    --tests=*) tests_regex="${1#*=}"; shift ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) cmake_args+=("$1"); shift ;;
  esac
done

# Under the sanitizers, the long accuracy runs labelled sanitizer_skip in tests/test_lists.cmake are
# left out (each entry says why, and which test runs its code instead); the ThreadSanitizer stage
# also leaves out those labelled tsan_skip, the AddressSanitizer stage those labelled asan_skip.
# ThreadSanitizer runs the tests whose code under test starts threads of plslam's own: the worker
# pool and the BA that uses it, the local mapper's thread with its pause and abort
# (LocalMapperThread), the map snapshot taken beside a writer (MapSnapshotConcurrent), the stereo extraction tasks, the image prefetch thread, synth's
# parallel rendering, `plslam run` in the default mode (RunDeterministic: the mapping and loop
# jobs beside tracking, two runs compared byte for byte) and with --free-running (RunConcurrent:
# tracking + local mapping thread + prefetch), and the robustness suites that run a threaded command (the image prefetch of
# `plslam run`, synth and bench stopped by a signal), the keyframe database (local mapping adds,
# tracking queries), a default run that relocalizes (RelocalizationConcurrent), and loop closing
# (LoopClosingConcurrent: its thread and global BA on a map, and a default run of `plslam run`
# with all threads; two such runs are compared byte for byte in Release), the
# browser viewer's server threads and its publisher beside a run (ViewerServer, LiveViewerRun); the suites on reading user input (InputRobustness,
# JsonStdoutRobustness, ConfigRobustness) test parsing and checks, not threads, and run in the
# other two stages. The sequential end-to-end accuracy runs
# are left to the other stages: in them local mapping runs in the tracking thread, and
# RunDeterministic, RunConcurrent and LoopClosingConcurrent cover every seam between the threads.
TSAN_SUITES='WorkerPool|LocalMapperThread|MapSnapshotConcurrent|BundleAdjustment|StereoPoints|FrameStream|LiveCapture|VideoDataset|SynthFormats|SynthDeterminism|RunConcurrent|RunDeterministic|TimeRobustness|SignalRobustness|KeyframeDatabase|RelocalizationConcurrent|LoopClosingConcurrent|ViewerServer|LiveViewerRun'
TSAN_TESTS="^(${TSAN_SUITES})\\."
# The test executables that hold them (tests/<folder> -> test_<folder>), plus the CLI they run: the
# TSan stage builds only these. A TSan suite in another folder stops the script (checked below),
# so no test can drop out of the stage silently.
TSAN_TARGETS='plslam test_core test_features test_io test_loop test_map test_mapping test_optim test_place test_robustness test_synth test_system test_viz'
for f in $(grep -rlE "^(TEST|TEST_F|TEST_P)\((${TSAN_SUITES})[A-Za-z]*," tests); do
  folder=$(echo "$f" | cut -d/ -f2)
  case " $TSAN_TARGETS " in
    *" test_$folder "*) ;;
    *) echo "test.sh: $f holds ThreadSanitizer tests, but test_$folder is not in TSAN_TARGETS" >&2; exit 2 ;;
  esac
done

case "$sanitize" in
  "") default_dir=build; build_type=Release ;;
  address|undefined|address,undefined|undefined,address) default_dir=build-asan; build_type=RelWithDebInfo ;;
  thread) default_dir=build-tsan; build_type=RelWithDebInfo ;;
  *) echo "test.sh: --sanitize takes address,undefined or thread, not '$sanitize'" >&2; exit 2 ;;
esac
BUILD_DIR=${BUILD_DIR:-$default_dir}

bash scripts/install-deps.sh
# Unity build: each batch of sources compiles as one translation unit, so the Eigen, OpenCV, Ceres
# and GoogleTest headers and their template instantiations are compiled once per batch instead of
# once per file. The suite builds about twice as fast, which keeps the three CI stages within
# their time; files must not clash in their anonymous namespaces (the build says so at once).
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE="$build_type" -DPLSLAM_SANITIZE="$sanitize" -DCMAKE_UNITY_BUILD=ON \
  ${sanitize:+-DPLSLAM_BUILD_BENCH=OFF} ${cmake_args[@]+"${cmake_args[@]}"} >/dev/null
build_targets=()
if [ -z "$tests_regex" ] && [ "$sanitize" = thread ]; then build_targets=(--target $TSAN_TARGETS); fi
cmake --build "$BUILD_DIR" -j"$(nproc)" ${build_targets[@]+"${build_targets[@]}"}
ctest_args=(--test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)")
if [ -z "$tests_regex" ] && [ "$sanitize" = thread ]; then tests_regex=$TSAN_TESTS; fi
if [ -n "$tests_regex" ]; then ctest_args+=(-R "$tests_regex"); fi
if [ "$sanitize" = thread ]; then
  ctest_args+=(-LE 'sanitizer_skip|tsan_skip')
elif [ -n "$sanitize" ]; then
  ctest_args+=(-LE 'sanitizer_skip|asan_skip')
fi
ctest "${ctest_args[@]}"
