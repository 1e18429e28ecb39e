#!/usr/bin/env bash
# Installs dependencies, builds and runs the test suite through ctest.
#
#   scripts/test.sh                              Release build in build/, the whole suite
#   scripts/test.sh --sanitize address,undefined ASan+UBSan build in build-asan/, the whole suite
#   scripts/test.sh --sanitize thread            TSan build in build-tsan/, the threaded tests
#   scripts/test.sh --sanitize thread --tests R  ... only the tests whose name matches regex R
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

# Under the sanitizers, the named long accuracy runs are left out: they run the same code as the
# shorter end-to-end runs, only longer, and their ATE bounds are checked by the Release stage.
#   RunEndToEnd.CorridorLinesLowerTheFrameToFrameError  6 corridor runs (300 s under ASan)
#   RunEndToEnd.Kitti01HighwayIsTrackedWithinBound      KITTI 01, the same path as KITTI 06
#   RunEndToEnd.SyntheticStreetTurnIsTracked            a rendered street at KITTI size (120 s under
#                                                     ASan); KITTI 06 and the kidnapped KITTI copies
#                                                     run the same sequential path here
#   RunDeterminism.Sequential*RunsAreByteIdentical  each runs plslam twice to compare the bytes;
#                                                     the same code as RunEndToEnd, which runs here
#   LoopRun.SequentialRunsWithALoopAreIdentical      likewise, with loop closing; the loop itself
#                                                     runs here in LoopClosingConcurrent
#   BenchSlamCli.QuickPreset...                       8 sequential runs of one office render (230 s
#                                                     under ASan); the bench's own code runs here in
#                                                     the other BenchSlamCli tests
#   RunVideo.ASyntheticVideoTracksLikeItsImageFolders two 120-frame sequential runs (160 s under
#                                                     ASan); video decoding runs here in
#                                                     RunVideo.AVideoPlayedAsACamera... and VideoDataset
#   RunEndToEnd.SyntheticOfficeIsTrackedWithSmallError the rendered office, sequential (80 s under
#                                                     ASan); RunConcurrent and LoopClosingConcurrent
#                                                     run the same scene here with every thread
#   Relocalization.KidnappedKittiCameraIsFoundAgainInTheSameMap  sequential (100 s under ASan);
#                                                     RelocalizationConcurrent runs the same kidnapping
#                                                     here, with local mapping's thread
#   BlackOut.*                                        a 480-frame office render and sequential runs of
#                                                     180 and 346 frames; the same relocalization code
#                                                     runs here in the kidnapped tests
#   RunEndToEnd.Kitti06IsTrackedWithinBound           sequential KITTI 06 (43 s under ASan): the
#                                                     kidnapped KITTI copies of Relocalization run the
#                                                     same sequential path here, RunConcurrent KITTI 06
#   BenchSlamCli.ConcurrentRunsAgreeWithASeparateRun... 4 concurrent runs compared as a spread (57 s
#                                                     under ASan, where thread timing widens it); the
#                                                     bench's runs and report run here in the SIGTERM test
#   TimeRobustness.HighwayStartedOneFrameLate...      KITTI 01 (26 s under ASan, 92 s under TSan), the
#                                                     same path as the KITTI 06 copies of the others
#   TimeRobustness.{SingleDroppedFrame,EverySecondFrameDropped}KeepsTracking,
#   TimeRobustness.BlankImageMidSequence...           frames dropped or blanked (37 s under ASan, 70 s
#                                                     under TSan): files missing at the start and the
#                                                     end, an unreadable image, a lost frame and a late
#                                                     start run here, through the same reader and
#                                                     prefetch thread
# (The CI run of 2026-11-26 took 56.7 of its 60 minutes; these two give back about 1.5. That of
# 2026-11-29 took 65 minutes; the last four give back about 2.)
SANITIZER_SKIP='^(RunEndToEnd\.(CorridorLinesLowerTheFrameToFrameError|Kitti01HighwayIsTrackedWithinBound|Kitti06IsTrackedWithinBound|SyntheticStreetTurnIsTracked|SyntheticOfficeIsTrackedWithSmallError)|Relocalization\.KidnappedKittiCameraIsFoundAgainInTheSameMap|BlackOut\..*|RunDeterminism\.Sequential(Kitti|Rendered)RunsAreByteIdentical|LoopRun\.SequentialRunsWithALoopAreIdentical|BenchSlamCli\.(QuickPresetReportsEveryConfigurationAndMetricAsSeparateSequentialRunsDo|ConcurrentRunsAgreeWithASeparateRunWithinTheirSpreadAndAnAnchorIsARow)|RunVideo\.ASyntheticVideoTracksLikeItsImageFolders|TimeRobustness\.(HighwayStartedOneFrameLateIsTrackedAtItsSpeed|SingleDroppedFrameKeepsTracking|EverySecondFrameDroppedKeepsTracking|BlankImageMidSequenceIsSkippedAndKeepsAlignment))$'
# ThreadSanitizer runs the tests whose code under test starts threads of plslam's own: the worker
# pool and the BA that uses it, the local mapper's thread with its pause and abort
# (LocalMapperThread), the map snapshot taken beside a writer (MapSnapshotConcurrent), the stereo extraction tasks, the image prefetch thread, synth's
# parallel rendering, `plslam run` in the default concurrent mode (tracking + local mapping +
# prefetch), and the robustness suites that run a threaded command (the image prefetch of
# `plslam run`, synth and bench stopped by a signal), the keyframe database (local mapping adds,
# tracking queries), a concurrent run that relocalizes (RelocalizationConcurrent), and loop closing
# (LoopClosingConcurrent: its thread and global BA on a map, and `plslam run` with all threads), the
# browser viewer's server threads and its publisher beside a run (ViewerServer, LiveViewerRun); the suites on reading user input (InputRobustness,
# JsonStdoutRobustness, ConfigRobustness) test parsing and checks, not threads, and run in the
# other two stages. The sequential end-to-end accuracy runs
# are left to the other stages: in them local mapping runs in the tracking thread, and
# RunConcurrent covers every seam between the threads.
TSAN_SUITES='WorkerPool|LocalMapperThread|MapSnapshotConcurrent|BundleAdjustment|StereoPoints|FrameStream|LiveCapture|VideoDataset|SynthFormats|SynthDeterminism|RunConcurrent|TimeRobustness|SignalRobustness|KeyframeDatabase|RelocalizationConcurrent|LoopClosingConcurrent|ViewerServer|LiveViewerRun'
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
# Under ThreadSanitizer the rendered office run of RunConcurrent is left out as well:
# LoopClosingConcurrent.RenderedOfficeLoopClosesAtTheRevisitOnly runs the same threads on the same
# scene, with loop closing and its global BA on top (109 s of the stage).
# (The TimeRobustness runs it leaves out are in SANITIZER_SKIP above.)
TSAN_SKIP='^(RunConcurrent\.SyntheticOfficeWithLocalMappingThread)$'
if [ "$sanitize" = thread ]; then
  ctest_args+=(-E "$SANITIZER_SKIP|$TSAN_SKIP")
elif [ -n "$sanitize" ]; then
  ctest_args+=(-E "$SANITIZER_SKIP")
fi
ctest "${ctest_args[@]}"
