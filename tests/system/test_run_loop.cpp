// End-to-end loop closing: `plslam run` on a rendered office loop (exact ground truth), with the
// loop-closing thread and its global BA. The render is 180 frames at 6.7 Hz (EuRoC's 20 Hz / 3, so
// that the sanitizer stages of CI can afford it), with 15 % of the loop travelled again after the
// return: the revisit lasts ~25 frames. With synth's default 3 % it lasted 5, and a concurrent run
// slowed by a sanitizer, with fewer keyframes, could end before the loop was confirmed. The
// sanitizer stages watch these runs: tracking, local mapping, loop detection, the essential
// graph, the global BA and the image prefetch all at once (ThreadSanitizer the default mode's,
// AddressSanitizer a --free-running one).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <memory>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

constexpr int kLoopFrames = 180;  // the office loop at 6.7 Hz with a 15 % overlap takes >= 172

class LoopRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<test::TempDir>();
    const auto r = test::run_cli("synth --out \"" + sequence().string() + "\" --scene office --preset euroc --fps " +
                                 fmt::format("{:.17g}", 20.0 / 3) + " --frames " + std::to_string(kLoopFrames) +
                                 " --loop --loop-overlap 0.15 --seed 1 --threads 2");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { tmp_.reset(); }
  static fs::path sequence() { return tmp_->path() / "loop"; }

  static nlohmann::json run(const fs::path& out, const std::string& extra = "") {
    const auto r = test::run_cli("run \"" + sequence().string() + "\" --out \"" + out.string() + "\" --quiet" + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(out / "stats.json");
    if (r.exit_code != 0 || !in) return {};
    return nlohmann::json::parse(in);
  }

  // Loops only where the ground truth revisits: the camera returns to its start at frame ~156 and
  // travels the first ~25 frames again. A loop is true when its two frames' cameras stand within
  // 2 m and look within 30 deg of each other; elsewhere on this loop, frames of the first 30 and
  // of the last 30 are >= 3 m apart. (A free-running run under ASan closed at frame 149, 1.3 m
  // behind frame 0 and 22 deg off, seeing its scene: a frame bound of 150 failed it.)
  static void expect_true_loops(const nlohmann::json& stats) {
    ASSERT_FALSE(stats.is_null());
    EXPECT_EQ(stats["tracked_frames"], kLoopFrames);
    ASSERT_GE(stats["loops"].size(), 1u) << stats.dump();
    const auto truth = io::read_trajectory(sequence() / "mav0" / "synth" / "left_camera.tum", io::TrajectoryFormat::kTum);
    ASSERT_EQ(truth.size(), static_cast<std::size_t>(kLoopFrames));
    for (const auto& l : stats["loops"]) {
      const auto& a = truth.at(l["frame"].get<std::size_t>()).T;
      const auto& b = truth.at(l["matched_frame"].get<std::size_t>()).T;
      const double view_deg = std::acos(std::clamp(a.linear().col(2).dot(b.linear().col(2)), -1.0, 1.0)) * 180 / M_PI;
      EXPECT_GE(l["frame"].get<int>(), kLoopFrames / 2) << l.dump();
      EXPECT_LE((a.translation() - b.translation()).norm(), 2.0) << l.dump();
      EXPECT_LE(view_deg, 30.0) << l.dump();
      EXPECT_GE(l["inliers"].get<int>(), 40) << l.dump();
    }
    EXPECT_GE(stats["global_ba_runs"].get<int>(), 1);
    EXPECT_EQ(stats["global_ba_ms"].size(), stats["global_ba_runs"].get<std::size_t>());
    EXPECT_EQ(stats["loop_correction_ms"].size(), stats["loops"].size());
    // A sanity bound against a wrong correction (decimetres), not the loop's gain, which the
    // sequential test bounds. A free-running run's map depends on thread timing: 60 runs, 4 at a
    // time on 2 cores: median 0.0094 m, p90 0.0116, max 0.0207; CI's ASan stage, with 57
    // keyframes instead of 65-70, measured 0.0163, 0.0200, 0.028.
    EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.04)
        << "keyframes " << stats["keyframes"] << ", lost " << stats["lost_events"] << ", relocalizations "
        << stats["relocalizations"].dump() << ", loops " << stats["loops"].dump();
  }

  // A default run whose global BA is merged 1 s of input time after the correction's end.
  // Each run writes its own config file: the identity test starts two at once in one folder.
  static nlohmann::json run_default(const fs::path& dir, const std::string& name) {
    const auto config = dir / (name + "_merge.yaml");
    std::ofstream(config) << "loop:\n  global_ba_merge_after_s: 1.0\n";
    return run(dir / name, " --config \"" + config.string() + "\"");
  }
  static void expect_merged_in_time(const nlohmann::json& a) {
    expect_true_loops(a);
    EXPECT_EQ(a["mode"], "deterministic");
    // Merged during the run, 1 s (6.7 frames at 6.7 Hz) after the correction's end, which comes
    // 2 frames after the keyframe's local BA, one to verify, and 2 after it began (a local BA in
    // flight may move a step by up to 2 frames).
    // Before it, the global BAs that refine the IMU's initialisation (the render's exact IMU), at
    // most two (imu.refine_after_s, imu.refine_again_after_s); the loop's is the last.
    const auto refinements = a["loop_closing"]["global_ba_inertial_refinements"].get<std::size_t>();
    EXPECT_LE(refinements, 2u);
    ASSERT_EQ(a["global_ba_merged_before_frames"].size(), 1u + refinements) << a.dump();
    const long merged_at = a["global_ba_merged_before_frames"].back().get<long>();
    const long loop_at = a["loops"][0]["frame"].get<long>();
    EXPECT_GE(merged_at, loop_at + 2 + 1 + 2 + 7);
    EXPECT_LE(merged_at, loop_at + 2 + 1 + 2 + 2 + 2 + 8);
    // The local BA met two frames after its keyframe costs accuracy at this render's 6.7 Hz (fewer
    // keyframes: mapping counts as busy while it is in flight): 0.0106-0.0120 m over 1196-1204
    // features (sequential 0.0068-0.0077; concurrent median 0.0094, p90 0.0116). At 20 Hz it does
    // not (docs/analysis/deterministic.md). A sanity bound, not the loop's gain.
    EXPECT_LT(a["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.014);
    EXPECT_EQ(a["local_mapping"]["local_ba_skipped"], 0);
  }

  static std::unique_ptr<test::TempDir> tmp_;
};

std::unique_ptr<test::TempDir> LoopRun::tmp_;

using LoopClosingConcurrent = LoopRun;

// One --free-running run, for the AddressSanitizer stage: the loop-closing thread as it runs
// there. A default run takes 202 s under ASan (every local BA waited for) against 90; the default
// mode's loop runs under ThreadSanitizer and in Release in DefaultRunClosesTheLoop* below (two
// runs compared in Release), and its correction steps under ASan in LoopCorrection.InThreeSteps*.
TEST_F(LoopClosingConcurrent, RenderedOfficeLoopClosesAtTheRevisitOnly) {
  test::TempDir out;
  const auto stats = run(out.path() / "run", " --free-running");
  expect_true_loops(stats);
  EXPECT_EQ(stats["mode"], "free-running");
}

TEST_F(LoopRun, SequentialRunsWithALoopAreIdentical) {
  test::TempDir out;
  auto a = run(out.path() / "a", " --sequential");
  auto b = run(out.path() / "b", " --sequential");
  expect_true_loops(a);
  // The loop's gain where it is reproducible: 0.0069 m with loop closing, 0.0171 without (Release).
  EXPECT_LT(a["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.0095);
  for (auto* s : {&a, &b}) {
    for (auto& l : (*s)["loops"]) l.erase("correction_ms");  // timings differ
  }
  EXPECT_EQ(a["loops"], b["loops"]);
  for (const char* f : {"trajectory.tum", "keyframes.tum", "map_points.ply", "map_lines.ply"}) {
    EXPECT_EQ(test::read_file(out.path() / "a" / f), test::read_file(out.path() / "b" / f)) << f;
  }
}

// The default mode with the loop: the local BAs, the loop's detection and verification, its
// essential graph and the global BA run in their own threads and meet tracking at frames fixed in
// advance (the correction begins at a meeting point after the keyframe's local BA, ends
// loop.correction_merge_after_frames later, and its global BA is merged before the first frame
// 1 s of input time after that). One run, for ThreadSanitizer's eyes (280 s there) and Release's;
// the identity test below runs two and compares them.
TEST_F(LoopClosingConcurrent, DefaultRunClosesTheLoopAndMergesItsGlobalBaAtItsFrame) {
  test::TempDir out;
  expect_merged_in_time(run_default(out.path(), "a"));
}

// Two default runs, side by side so that their threads' timing differs, are identical, loop
// closing and global BA included: the meeting frames are the same in both.
TEST_F(LoopClosingConcurrent, DefaultRunsWithALoopAreIdentical) {
  test::TempDir out;
  auto b_async = std::async(std::launch::async, [&] { return run_default(out.path(), "b"); });
  auto a = run_default(out.path(), "a");
  auto b = b_async.get();
  expect_merged_in_time(a);
  for (auto* s : {&a, &b}) {
    for (auto& l : (*s)["loops"]) l.erase("correction_ms");  // timings differ
  }
  EXPECT_EQ(a["loops"], b["loops"]);
  EXPECT_EQ(a["global_ba_merged_before_frames"], b["global_ba_merged_before_frames"]);
  for (const char* f : {"trajectory.tum", "keyframes.tum", "map_points.ply", "map_lines.ply"}) {
    EXPECT_EQ(test::read_file(out.path() / "a" / f), test::read_file(out.path() / "b" / f)) << f;
  }
}

// The switch only: a short render of its own (the loop render costs minutes under the sanitizers).
TEST(LoopClosingSwitch, NoLoopClosingLeavesTheThreadOut) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "office";
  ASSERT_EQ(test::run_cli("synth --out \"" + seq.string() + "\" --scene office --frames 30 --seed 3").exit_code, 0);
  const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + (tmp.path() / "run").string() +
                               "\" --quiet --no-loop-closing");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto stats = nlohmann::json::parse(test::read_file(tmp.path() / "run" / "stats.json"));
  EXPECT_EQ(stats["loop_closing"]["enabled"], false);
  EXPECT_EQ(stats["loops"].size(), 0u);
  EXPECT_EQ(stats["global_ba_runs"], 0);
  EXPECT_NE(r.out.find("loops 0"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace plslam
