// `plslam eval` through the real binary: output shape, plots, formats and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/synthetic_trajectories.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam::eval {
namespace {

using io::TrajectoryFormat;
using plslam::test::run_cli;

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// Shell-quoted path. (Appending avoids GCC 12's false -Wrestrict on "'" + std::string.)
std::string q(const std::filesystem::path& p) {
  std::string s(1, '\'');
  s.append(p.string());
  s.push_back('\'');
  return s;
}

int count_lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

// Ground truth (helix) and an estimate with a small wobble, both in TUM format.
struct Files {
  plslam::test::TempDir dir;
  std::filesystem::path gt = dir.path() / "gt.tum";
  std::filesystem::path est = dir.path() / "est.tum";
  Files() {
    const Trajectory g = test::helix(300);
    Trajectory e = g;
    for (std::size_t i = 0; i < e.size(); ++i) {
      e[i].t += 0.003;
      e[i].T.translation() += 0.02 * Eigen::Vector3d(std::sin(0.1 * i), std::cos(0.13 * i), 0.0);
    }
    io::write_trajectory(gt, g, TrajectoryFormat::kTum);
    io::write_trajectory(est, e, TrajectoryFormat::kTum);
  }
};

TEST(EvalCli, JsonHasExactlyTheDocumentedKeys) {
  Files f;
  const auto r = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"ape_trans_m", "pairs", "rpe_rot_deg", "rpe_trans_m"}));
  EXPECT_EQ(j["pairs"].get<int>(), 300);
  for (const char* k : {"ape_trans_m", "rpe_trans_m", "rpe_rot_deg"}) {
    std::vector<std::string> names;
    for (const auto& [n, v] : j[k].items()) names.push_back(n);
    EXPECT_EQ(names, (std::vector<std::string>{"max", "mean", "median", "min", "rmse", "sse", "std"})) << k;
  }
  EXPECT_GT(j["ape_trans_m"]["rmse"].get<double>(), 0.005);
  EXPECT_LT(j["ape_trans_m"]["rmse"].get<double>(), 0.03);
  EXPECT_NE(r.err.find("matched 300 pose pairs"), std::string::npos) << r.err;
}

// tracking.png from a run's frames.csv: drawn with the keyframes; a broken log is refused.
TEST(EvalCli, PlotsTheFrameLogNextToTheError) {
  Files f;
  const Trajectory g = test::helix(300);
  std::string csv = "frame,timestamp,state,tracked,keyframe,keyframe_reason,point_inliers,line_inliers,reference_tracked,"
                    "keyframe_threshold,delta_pid,speed_mps,tracked_close,untracked_close,local_keyframes,local_points,"
                    "local_lines,stereo_points,stereo_lines,tracking_ms\n";
  for (std::size_t i = 0; i < g.size(); ++i) {
    const bool kf = i % 10 == 0;
    csv += fmt::format("{},{:.9f},OK,1,{},{},{},{},400,{},0,1.0,150,200,5,2000,100,800,120,20.0\n", i, g[i].t, kf ? 1 : 0,
                       kf ? "inlier-ratio" : "", 300 + static_cast<int>(i % 10) * 10, 40, 300);
  }
  const auto frames = f.dir.path() / "frames.csv";
  write_text(frames, csv);
  const auto dir = plslam::test::artifacts_dir() / "eval_cli_tracking";
  const auto r = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat img = cv::imread((dir / "tracking.png").string());
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.rows, 1200);
  cv::Mat red;  // keyframe markers are red (BGR 40, 39, 214)
  cv::inRange(img, cv::Scalar(30, 29, 200), cv::Scalar(50, 49, 230), red);
  EXPECT_GT(cv::countNonZero(red), 300);

  write_text(frames, "frame,timestamp,keyframe\n0,1.0\n");
  const auto bad = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("frames.csv: line 2: 2 cells, the header has 3"), std::string::npos) << bad.err;
  write_text(frames, "a,b\n1,2\n");
  EXPECT_NE(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames)).err.find("no 'frame' column"),
            std::string::npos);
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --frames " + q(frames)).exit_code, 2);  // needs --plot
}

TEST(EvalCli, HumanReadableByDefault) {
  Files f;
  const auto r = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --align sim3 --rpe-delta 2 --rpe-unit m --all-pairs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("APE trans"), std::string::npos);
  EXPECT_NE(r.out.find("sim3, scale"), std::string::npos);
  EXPECT_NE(r.out.find("RPE delta      2 m, all pairs"), std::string::npos) << r.out;
}

TEST(EvalCli, WritesPlots) {
  Files f;
  const auto dir = plslam::test::artifacts_dir() / "eval_cli_helix";
  const auto r = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"trajectory.png", "ape.png", "rpe.png"}) {
    const cv::Mat img = cv::imread((dir / name).string());
    ASSERT_FALSE(img.empty()) << name;
    EXPECT_GT(img.cols, 800);
    // A real drawing: plenty of non-white pixels, and not everything ink.
    cv::Mat grey;
    cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
    const double ink = 1.0 - cv::countNonZero(grey > 250) / static_cast<double>(grey.total());
    EXPECT_GT(ink, 0.02) << name;
    EXPECT_LT(ink, 0.5) << name;
  }
}

TEST(EvalCli, PlotsOfTheReferenceTrajectories) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto evo = data / "trajectories" / "evo";
  const auto base = plslam::test::artifacts_dir();
  EXPECT_EQ(run_cli("eval --gt " + q(evo / "KITTI_00_gt.txt") + " --est " + q(evo / "KITTI_00_ORB.txt") +
                    " --kitti-metric --plot " + q(base / "eval_kitti00_orb")).exit_code, 0);
  EXPECT_EQ(run_cli("eval --gt " + q(evo / "V102_groundtruth.csv") + " --est " + q(evo / "V102.txt") +
                    " --align sim3 --rpe-delta 1 --rpe-unit m --plot " + q(base / "eval_v102_sim3")).exit_code, 0);
  EXPECT_TRUE(std::filesystem::exists(base / "eval_kitti00_orb" / "trajectory.png"));
  EXPECT_TRUE(std::filesystem::exists(base / "eval_v102_sim3" / "rpe.png"));
}

TEST(EvalCli, BodyToCamTurnsEurocGroundTruthIntoCameraPoses) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto yaml = data / "euroc" / "V1_01_easy_micro" / "mav0" / "cam0" / "sensor.yaml";
  const Eigen::Isometry3d T_BS = io::read_euroc_T_BS(yaml);
  EXPECT_NEAR(T_BS(0, 3), -0.0216401454975, 1e-12);
  EXPECT_NEAR(T_BS(1, 0), 0.999557249008, 1e-6);
  plslam::test::TempDir dir;
  const Trajectory body = test::helix(100);
  io::write_trajectory(dir.path() / "gt.csv", body, TrajectoryFormat::kEuroc);
  io::write_trajectory(dir.path() / "cam.tum", io::body_to_sensor(body, T_BS), TrajectoryFormat::kTum);
  const std::string base = "eval --gt " + q(dir.path() / "gt.csv") + " --est " + q(dir.path() / "cam.tum") +
                           " --align none --json";
  const auto with = run_cli(base + " --gt-body-to-cam " + q(yaml));
  const auto without = run_cli(base);
  ASSERT_EQ(with.exit_code, 0) << with.err;
  ASSERT_EQ(without.exit_code, 0) << without.err;
  EXPECT_LT(nlohmann::json::parse(with.out)["ape_trans_m"]["max"].get<double>(), 1e-6);
  EXPECT_GT(nlohmann::json::parse(without.out)["ape_trans_m"]["max"].get<double>(), 0.01);
}

TEST(EvalCli, KittiAgainstStampedPairsByIndex) {
  plslam::test::TempDir dir;
  const Trajectory g = test::helix(50);
  io::write_trajectory(dir.path() / "gt.kitti", g, TrajectoryFormat::kKitti);
  io::write_trajectory(dir.path() / "est.tum", g, TrajectoryFormat::kTum);
  const auto ok = run_cli("eval --gt " + q(dir.path() / "gt.kitti") + " --est " + q(dir.path() / "est.tum") + " --json");
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(ok.out)["pairs"].get<int>(), 50);
  io::write_trajectory(dir.path() / "short.tum", Trajectory(g.begin(), g.begin() + 40), TrajectoryFormat::kTum);
  const auto bad = run_cli("eval --gt " + q(dir.path() / "gt.kitti") + " --est " + q(dir.path() / "short.tum"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("pair by index"), std::string::npos) << bad.err;
}

struct BadInput {
  const char* name;
  const char* gt_text;
  const char* est_text;
  const char* message;
};

class EvalCliBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(EvalCliBadInput, OneLineErrorAndExitCode2) {
  const auto& c = GetParam();
  plslam::test::TempDir dir;
  const bool kitti = std::string(c.name).rfind("kitti", 0) == 0;
  const auto gt = dir.path() / (kitti ? "gt.kitti" : "gt.tum");
  const auto est = dir.path() / (kitti ? "est.kitti" : "est.tum");
  write_text(gt, c.gt_text);
  write_text(est, c.est_text);
  const auto r = run_cli("eval --gt " + q(gt) + " --est " + q(est));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

constexpr const char* kGood =
    "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.2 1 1 0 0 0 0 1\n0.3 0 1 1 0 0 0 1\n0.4 2 1 1 0 0 0 1\n";

INSTANTIATE_TEST_SUITE_P(
    Cases, EvalCliBadInput,
    ::testing::Values(
        BadInput{"fewer_than_3_pairs", kGood, "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n9 1 1 0 0 0 0 1\n", "only 2 pose pairs"},
        BadInput{"empty", kGood, "", "empty trajectory"},
        BadInput{"malformed", kGood, "0 0 0 0 0 0 0 1\n0.1 1 x 0 0 0 0 1\n", "is not a number"},
        BadInput{"nan", kGood, "0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n", "non-finite"},
        BadInput{"unsorted", kGood, "0.2 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.3 1 0 0 0 0 0 1\n", "not after"},
        BadInput{"kitti_mismatched_lengths", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n1 0 0 2 0 1 0 0 0 0 1 0\n1 0 0 3 0 1 0 0 0 0 1 1\n",
                 "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n1 0 0 2 0 1 0 0 0 0 1 0\n", "4 poses and the estimate 3"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(EvalCli, BadOptionsExit2) {
  Files f;
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --align affine").exit_code, 2);
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --rpe-unit deg").exit_code, 2);
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --rpe-delta 1.5").exit_code, 2);
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --kitti-metric").exit_code, 2);  // 3 m of path
  EXPECT_EQ(run_cli("eval --gt /nonexistent.tum --est " + q(f.est)).exit_code, 2);
}

}  // namespace
}  // namespace plslam::eval
