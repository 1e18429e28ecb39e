// End-to-end: `plslam run` on a short synthetic sequence (always) and on KITTI 06 (when the shared
// data is there), checking the outputs and ATE bounds.
#include <algorithm>
#include <array>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/eval/frame_log.h"
#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

std::size_t count_lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  std::string line;
  while (std::getline(in, line)) n += !line.empty() && line[0] != '#';
  return n;
}

std::string head(const fs::path& p, int lines) {
  std::ifstream in(p);
  std::string out, line;
  for (int i = 0; i < lines && std::getline(in, line); ++i) out += line + "\n";
  return out;
}

void expect_outputs(const fs::path& out, std::size_t frames) {
  EXPECT_EQ(count_lines(out / "trajectory.tum"), frames);
  EXPECT_GT(count_lines(out / "keyframes.tum"), 0u);
  EXPECT_NE(head(out / "map_points.ply", 6).find("element vertex"), std::string::npos);
  EXPECT_NE(head(out / "map_lines.ply", 6).find("element vertex"), std::string::npos);
  const auto stats = read_json(out / "stats.json");
  for (const char* key : {"frames", "tracked_frames", "lost_events", "keyframes", "map_points", "map_lines",
                          "tracking_ms", "stages_ms", "local_ba_ms"}) {
    EXPECT_TRUE(stats.contains(key)) << key;
  }
  for (const char* key : {"median", "mean", "p90", "max"}) EXPECT_TRUE(stats["tracking_ms"].contains(key)) << key;
  for (const char* key : {"extraction", "stereo_matching", "track_motion", "track_local_map", "pose_optimization"}) {
    EXPECT_TRUE(stats["stages_ms"].contains(key)) << key;
  }
}

TEST(RunEndToEnd, SyntheticOfficeIsTrackedWithSmallError) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "office";
  const auto synth = test::run_cli("synth --out \"" + seq.string() + "\" --scene office --frames 120 --seed 3");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const auto out = tmp.path() / "run";
  const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + out.string() + "\" --quiet --sequential");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_outputs(out, 120);
  const auto stats = read_json(out / "stats.json");
  EXPECT_EQ(stats["tracked_frames"], 120);
  EXPECT_EQ(stats["lost_events"], 0);
  EXPECT_GT(stats["map_lines"].get<int>(), 0);
  // Under 1 % of the path length (the bound), with the exact rendered ground truth.
  const auto info = test::run_cli("info --json \"" + seq.string() + "\"");
  const double path = nlohmann::json::parse(info.out)["gt_path_length_m"].get<double>();
  const double ate = stats["accuracy"]["ape_trans_m"]["rmse"].get<double>();
  RecordProperty("ate_m", std::to_string(ate));
  RecordProperty("path_m", std::to_string(path));
  EXPECT_LT(ate, 0.01 * path);
  // The pose covariance (frames.csv cov_*): every tracked frame but the first (which defines the
  // world) has one, and it is consistent with the exact ground truth, mean NEES within 0.3-3x of
  // 6 (measured 5.3 on the 480-frame office loop).
  const auto log = eval::read_frame_log(out / "frames.csv");
  ASSERT_EQ(log.header.back(), "cov_rz_rz");
  const auto var_tx = log.numbers("cov_tx_tx"), var_rz = log.numbers("cov_rz_rz");
  EXPECT_EQ(var_tx.front(), 0.0);
  for (std::size_t i = 1; i < var_tx.size(); ++i) {
    EXPECT_GT(var_tx[i], 0.0) << i;
    EXPECT_LT(var_tx[i], 1e-4) << i;  // under 1 cm of standard deviation
    EXPECT_GT(var_rz[i], 0.0) << i;
  }
  const auto& nees = stats["accuracy"]["motion_nees"];
  EXPECT_EQ(nees["motions"], 118);
  EXPECT_GT(nees["mean"].get<double>(), 0.3 * 6);
  EXPECT_LT(nees["mean"].get<double>(), 3.0 * 6);
}

// Runs a 51-frame KITTI excerpt with --sequential (reproducible), checks every frame is tracked
// and returns the ATE (se3, m).
double run_kitti_sequential(const fs::path& data, const std::string& sequence) {
  test::TempDir tmp;
  const auto out = tmp.path() / "run";
  const auto r = test::run_cli("run \"" + (data / "kitti/sequences" / sequence).string() + "\" --out \"" +
                               out.string() + "\" --quiet --sequential");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return 1e9;
  expect_outputs(out, 51);
  EXPECT_EQ(count_lines(out / "trajectory.kitti"), 51u);
  const auto stats = read_json(out / "stats.json");
  EXPECT_EQ(stats["tracked_frames"], 51);
  EXPECT_EQ(stats["lost_events"], 0);
  return stats["accuracy"]["ape_trans_m"]["rmse"].get<double>();
}

TEST(RunEndToEnd, Kitti06IsTrackedWithinBound) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const double ate = run_kitti_sequential(data, "06");
  RecordProperty("ate_m", std::to_string(ate));
  // ORB-SLAM3 gets 0.042 m on these frames and the target is 0.063 m (1.5x); sequential
  // runs give 0.021-0.028 m. Letting the far points' stereo matches constrain the scale gave 0.10.
  EXPECT_LT(ate, 0.063);
}

TEST(RunEndToEnd, Kitti01HighwayIsTrackedWithinBound) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const double ate = run_kitti_sequential(data, "01");
  RecordProperty("ate_m", std::to_string(ate));
  // ORB-SLAM3: 0.75 m; the target 1.1 m; sequential runs give 0.36-0.38 m (1.04 m with
  // every far stereo match as a constraint).
  EXPECT_LT(ate, 0.75);
}

// The synthetic street's first turn (KITTI layout, 8 m/s, frames 40-60) ramps the yaw rate up by
// about 1 degree per frame per frame: 12 px of unexpected image motion, outside the motion
// model's window. Motion-model tracking then has to notice its low inlier share and search again
// wider; before it did, tracking carried on with poses off by 2 degrees per frame (ATE 2.8 m).
TEST(RunEndToEnd, SyntheticStreetTurnIsTracked) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "street";
  const auto synth =
      test::run_cli("synth --out \"" + seq.string() + "\" --scene street --preset kitti --frames 70 --seed 1");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const auto kitti = seq / "sequences" / "00";
  const auto out = tmp.path() / "run";
  const auto r = test::run_cli("run \"" + kitti.string() + "\" --out \"" + out.string() + "\" --quiet --sequential");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto stats = read_json(out / "stats.json");
  EXPECT_EQ(stats["tracked_frames"], 70);
  EXPECT_EQ(stats["lost_events"], 0);
  const auto info = test::run_cli("info --json \"" + kitti.string() + "\"");
  const double path = nlohmann::json::parse(info.out)["gt_path_length_m"].get<double>();
  const double ate = stats["accuracy"]["ape_trans_m"]["rmse"].get<double>();
  RecordProperty("ate_m", std::to_string(ate));
  EXPECT_LT(ate, 0.005 * path);
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Lines must earn their cost where corners are scarce: on the synthetic corridor, runs with lines
// have a lower frame-to-frame error (RPE over one frame, translation and rotation) than
// `--no-lines` runs. Medians of three runs each, because runs are not bit-reproducible (thread
// scheduling in the parallel solver and extraction); single runs overlap only at their tails.
TEST(RunEndToEnd, CorridorLinesLowerTheFrameToFrameError) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "corridor";
  const auto synth = test::run_cli("synth --out \"" + seq.string() + "\" --scene corridor --frames 200 --seed 3");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  std::array<std::vector<double>, 2> rpe_trans, rpe_rot;  // [0] lines, [1] --no-lines
  for (int run = 0; run < 3; ++run) {
    for (int no_lines = 0; no_lines < 2; ++no_lines) {
      const auto out = tmp.path() / ("run" + std::to_string(run) + "_" + std::to_string(no_lines));
      const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + out.string() + "\" --quiet --sequential" +
                                   (no_lines ? " --no-lines" : ""));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const auto stats = read_json(out / "stats.json");
      EXPECT_EQ(stats["tracked_frames"], 200);
      EXPECT_EQ(stats["lost_events"], 0);
      const auto& acc = stats["accuracy"];
      rpe_trans[static_cast<std::size_t>(no_lines)].push_back(acc["rpe_trans_m"]["rmse"].get<double>());
      rpe_rot[static_cast<std::size_t>(no_lines)].push_back(acc["rpe_rot_deg"]["rmse"].get<double>());
    }
  }
  const double t_lines = median_of(rpe_trans[0]), t_points = median_of(rpe_trans[1]);
  const double r_lines = median_of(rpe_rot[0]), r_points = median_of(rpe_rot[1]);
  RecordProperty("rpe_trans_lines_m", std::to_string(t_lines));
  RecordProperty("rpe_trans_no_lines_m", std::to_string(t_points));
  RecordProperty("rpe_rot_lines_deg", std::to_string(r_lines));
  RecordProperty("rpe_rot_no_lines_deg", std::to_string(r_points));
  // Measured (6 pairs): translation 0.0089 vs 0.0108 m, rotation 0.115 vs 0.140 deg.
  EXPECT_LT(t_lines, t_points);
  EXPECT_LT(r_lines, r_points);
}

TEST(RunEndToEnd, UnknownConfigKeyIsAnErrorNamingIt) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto cfg = tmp.path() / "bad.yaml";
  std::ofstream(cfg) << "keyframe:\n  ratio: 0.75\n  pidd: true\n";
  const auto r = test::run_cli("run \"" + (data / "kitti/sequences/06").string() + "\" --out \"" +
                               (tmp.path() / "o").string() + "\" --config \"" + cfg.string() + "\"");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown key 'keyframe.pidd'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
}

TEST(RunEndToEnd, ShippedConfigsAreValid) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  for (const char* name : {"euroc.yaml", "kitti.yaml"}) {
    test::TempDir tmp;
    const fs::path cfg = fs::path(PLSLAM_SOURCE_DIR) / "config" / name;
    const auto r = test::run_cli("run \"" + (data / "kitti/sequences/06").string() + "\" --max-frames 3 --quiet --out \"" +
                                 (tmp.path() / "o").string() + "\" --config \"" + cfg.string() + "\"");
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
  }
}

TEST(RunEndToEnd, MissingDatasetIsExitCode2) {
  test::TempDir tmp;
  const auto r = test::run_cli("run /nonexistent/seq --out \"" + (tmp.path() / "o").string() + "\"");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no such folder"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace plslam
