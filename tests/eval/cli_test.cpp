// `plslam eval` through the real binary: output shape, plots, formats and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
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
  EXPECT_EQ(keys, (std::vector<std::string>{"alignment", "ape_trans_m", "coverage", "pairs", "rpe_rot_deg", "rpe_trans_m"}));
  EXPECT_EQ(j["alignment"], "se3");
  EXPECT_NEAR(j["coverage"].get<double>(), 1.0, 0.01);
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

// frames.csv's columns up to tracking_ms.
constexpr const char* kFrameLogColumns =
    "frame,timestamp,state,tracked,keyframe,keyframe_reason,point_inliers,line_inliers,reference_tracked,"
    "keyframe_threshold,delta_pid,speed_mps,tracked_close,untracked_close,local_keyframes,local_points,"
    "local_lines,stereo_points,stereo_lines,tracking_ms";

// tracking.png from a run's frames.csv: drawn with the keyframes; a broken log is refused.
TEST(EvalCli, PlotsTheFrameLogNextToTheError) {
  Files f;
  const Trajectory g = test::helix(300);
  std::string csv = std::string(kFrameLogColumns) + "\n";  // as runs wrote it before the map_* and rss_mb columns
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
  EXPECT_FALSE(std::filesystem::exists(dir / "resources.png"));  // no map_* / rss_mb columns: no resources plot

  write_text(frames, "frame,timestamp,keyframe\n0,1.0\n");
  const auto bad = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("frames.csv: line 2: 2 cells, the header has 3"), std::string::npos) << bad.err;
  write_text(frames, "a,b\n1,2\n");
  EXPECT_NE(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames)).err.find("no 'frame' column"),
            std::string::npos);
  EXPECT_EQ(run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --frames " + q(frames)).exit_code, 2);  // needs --plot
}

// resources.png from a long run's frames.csv (map_* and rss_mb columns): the memory curve is drawn
// in the middle panel.
TEST(EvalCli, PlotsMemoryTimeAndMapSizeOfALongRun) {
  Files f;
  const Trajectory g = test::helix(300);
  std::string csv = std::string(kFrameLogColumns) + ",map_keyframes,map_points,map_lines,rss_mb\n";
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double grow = static_cast<double>(std::min<std::size_t>(i, 150));
    csv += fmt::format("{},{:.9f},OK,1,0,,300,40,400,200,0,1.0,150,200,5,2000,100,800,120,{:.1f},{},{},{},{:.1f}\n", i,
                       g[i].t, 20.0 + static_cast<double>(i % 7), 1 + i / 10, 1000 + 10 * grow, 100 + grow, 200 + grow);
  }
  const auto frames = f.dir.path() / "frames.csv";
  write_text(frames, csv);
  const auto dir = plslam::test::artifacts_dir() / "eval_cli_resources";
  std::filesystem::remove_all(dir);
  const auto r = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir) + " --frames " + q(frames));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("resources.png"), std::string::npos) << r.err;
  const cv::Mat img = cv::imread((dir / "resources.png").string());
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.rows, 1200);
  cv::Mat red;  // the resident memory is drawn red (BGR 40, 39, 214) in the middle panel
  cv::inRange(img(cv::Rect(0, 400, img.cols, 400)), cv::Scalar(30, 29, 200), cv::Scalar(50, 49, 230), red);
  EXPECT_GT(cv::countNonZero(red), 500);
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

// An estimate that covers little of the ground truth would score well for the wrong reason: eval
// says how much it covers, refuses under 20 % or 10 pairs, and --allow-partial scores it anyway.
TEST(EvalCli, CoverageIsReportedAndAShortEstimateRefusedUnlessAllowed) {
  plslam::test::TempDir dir;
  const Trajectory g = test::helix(300);
  io::write_trajectory(dir.path() / "gt.tum", g, TrajectoryFormat::kTum);
  io::write_trajectory(dir.path() / "half.tum", Trajectory(g.begin(), g.begin() + 151), TrajectoryFormat::kTum);
  io::write_trajectory(dir.path() / "short.tum", Trajectory(g.begin() + 100, g.begin() + 130), TrajectoryFormat::kTum);
  const std::string gt = " --gt " + q(dir.path() / "gt.tum");

  const auto half = run_cli("eval --json" + gt + " --est " + q(dir.path() / "half.tum"));
  ASSERT_EQ(half.exit_code, 0) << half.err;
  EXPECT_NEAR(nlohmann::json::parse(half.out)["coverage"].get<double>(), 150.0 / 299.0, 1e-9);
  EXPECT_NE(run_cli("eval" + gt + " --est " + q(dir.path() / "half.tum")).out.find("coverage       50.2 %"),
            std::string::npos);

  const auto refused = run_cli("eval" + gt + " --est " + q(dir.path() / "short.tum"));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(count_lines(refused.err), 1) << refused.err;
  EXPECT_NE(refused.err.find("covers 10 % of the ground truth with 30 pose pairs"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--allow-partial"), std::string::npos) << refused.err;
  EXPECT_TRUE(refused.out.empty());

  const auto allowed = run_cli("eval --json --allow-partial" + gt + " --est " + q(dir.path() / "short.tum"));
  ASSERT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_EQ(nlohmann::json::parse(allowed.out)["pairs"].get<int>(), 30);
}

// A failed start writes identity poses; degenerate ground truth stands still. Aligning either
// would report an excellent error (or a Sim(3) scale of 0): refused unless --allow-degenerate,
// which scores without alignment and says so.
TEST(EvalCli, DegenerateAlignmentIsRefusedUnlessAllowed) {
  plslam::test::TempDir dir;
  const Trajectory g = test::helix(100);
  Trajectory still = g;
  for (auto& p : still) p.T = Eigen::Isometry3d::Identity();
  io::write_trajectory(dir.path() / "gt.tum", g, TrajectoryFormat::kTum);
  io::write_trajectory(dir.path() / "still.tum", still, TrajectoryFormat::kTum);
  const std::string gt = q(dir.path() / "gt.tum"), st = q(dir.path() / "still.tum");
  for (const char* align : {"se3", "sim3"}) {
    const auto est_still = run_cli(fmt::format("eval --align {} --gt {} --est {}", align, gt, st));
    EXPECT_EQ(est_still.exit_code, 2) << align;
    EXPECT_NE(est_still.err.find("degenerate alignment: the paired estimated positions all coincide"),
              std::string::npos) << est_still.err;
    const auto gt_still = run_cli(fmt::format("eval --align {} --gt {} --est {}", align, st, gt));
    EXPECT_EQ(gt_still.exit_code, 2) << align;
    EXPECT_NE(gt_still.err.find("ground-truth positions all coincide"), std::string::npos) << gt_still.err;
  }
  const auto allowed = run_cli(fmt::format("eval --json --align sim3 --allow-degenerate --gt {} --est {}", gt, st));
  ASSERT_EQ(allowed.exit_code, 0) << allowed.err;
  const auto j = nlohmann::json::parse(allowed.out);
  EXPECT_EQ(j["alignment"], "none");
  EXPECT_NE(j["degenerate"].get<std::string>().find("coincide"), std::string::npos);
  EXPECT_GT(j["ape_trans_m"]["max"].get<double>(), 0.5);  // the unaligned error, not a perfect score
  // --align none never aligns, so nothing is degenerate.
  EXPECT_EQ(run_cli(fmt::format("eval --align none --gt {} --est {}", gt, st)).exit_code, 0);
}

// Plots are written whole or not at all: a write that fails leaves no file under its name.
TEST(EvalCli, AFailedPlotWriteLeavesNoFileAndFails) {
  Files f;
  const auto dir = f.dir.path() / "plots";
  ::setenv("PLSLAM_FAIL_WRITE", "ape.png", 1);
  const auto failed = run_cli("eval --gt " + q(f.gt) + " --est " + q(f.est) + " --plot " + q(dir));
  ::unsetenv("PLSLAM_FAIL_WRITE");
  EXPECT_NE(failed.exit_code, 0);
  EXPECT_NE(failed.err.find("ape.png"), std::string::npos) << failed.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "ape.png"));
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
  }
}

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
