// End-to-end loop closing: `plslam run` on a rendered office loop (exact ground truth), with the
// loop-closing thread and its global BA. The render is 480 frames (the shortest office loop synth
// makes); the runs read every third frame, 160 frames at 6.7 Hz, so that the sanitizer stages of CI
// can afford them. The concurrent run is the one the ThreadSanitizer stage watches: tracking, local
// mapping, loop closing, global BA and the image prefetch all at once.
#include <fstream>
#include <memory>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

constexpr int kLoopEvery = 3;
constexpr int kLoopFrames = 480 / kLoopEvery;

// An EuRoC copy of `src` with every kLoopEvery-th frame (images linked, ground truth shared).
void decimate_euroc(const fs::path& src, const fs::path& dst) {
  for (const char* cam : {"cam0", "cam1"}) {
    const fs::path in = src / "mav0" / cam, out = dst / "mav0" / cam;
    fs::create_directories(out / "data");
    fs::copy_file(in / "sensor.yaml", out / "sensor.yaml");
    std::ifstream csv(in / "data.csv");
    std::ofstream copy(out / "data.csv");
    std::string line;
    std::getline(csv, line);
    copy << line << "\n";
    for (int i = 0; std::getline(csv, line); ++i) {
      if (i % kLoopEvery != 0) continue;
      copy << line << "\n";
      std::string file = line.substr(line.find(',') + 1);
      if (!file.empty() && file.back() == '\r') file.pop_back();
      fs::create_symlink(in / "data" / file, out / "data" / file);
    }
  }
  for (const char* gt : {"state_groundtruth_estimate0", "synth"}) {
    fs::create_directory_symlink(src / "mav0" / gt, dst / "mav0" / gt);
  }
}

class LoopRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<test::TempDir>();
    const auto render = tmp_->path() / "render";
    const auto r = test::run_cli("synth --out \"" + render.string() +
                                 "\" --scene office --preset euroc --frames 480 --loop --seed 1 --threads 2");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    decimate_euroc(render, sequence());
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

  // Loops only where the ground truth revisits: the last frames return to the first ones.
  static void expect_true_loops(const nlohmann::json& stats) {
    ASSERT_FALSE(stats.is_null());
    EXPECT_EQ(stats["tracked_frames"], kLoopFrames);
    ASSERT_GE(stats["loops"].size(), 1u) << stats.dump();
    for (const auto& l : stats["loops"]) {
      EXPECT_GE(l["frame"].get<int>(), kLoopFrames - 30) << l.dump();
      EXPECT_LE(l["matched_frame"].get<int>(), 30) << l.dump();
      EXPECT_GE(l["inliers"].get<int>(), 40) << l.dump();
    }
    EXPECT_GE(stats["global_ba_runs"].get<int>(), 1);
    EXPECT_EQ(stats["global_ba_ms"].size(), stats["global_ba_runs"].get<std::size_t>());
    EXPECT_EQ(stats["loop_correction_ms"].size(), stats["loops"].size());
    // Without loop closing this run ends 2-3 cm off (bench/loop_closing: 1/3 of it with).
    EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.02);
  }

  static std::unique_ptr<test::TempDir> tmp_;
};

std::unique_ptr<test::TempDir> LoopRun::tmp_;

using LoopClosingConcurrent = LoopRun;

TEST_F(LoopClosingConcurrent, RenderedOfficeLoopClosesAtTheRevisitOnly) {
  test::TempDir out;
  expect_true_loops(run(out.path() / "run"));
}

TEST_F(LoopRun, SequentialRunsWithALoopAreIdentical) {
  test::TempDir out;
  auto a = run(out.path() / "a", " --sequential");
  auto b = run(out.path() / "b", " --sequential");
  expect_true_loops(a);
  for (auto* s : {&a, &b}) {
    for (auto& l : (*s)["loops"]) l.erase("correction_ms");  // timings differ
  }
  EXPECT_EQ(a["loops"], b["loops"]);
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
