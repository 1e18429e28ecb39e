// The bench's plan, configurations, per-run scoring and summary, on hand-made run folders.
#include <gtest/gtest.h>

#include <fstream>

#include "plslam/bench/slam_bench.h"
#include "plslam/bench/slam_figures.h"
#include "plslam/core/error.h"
#include "plslam/eval/evaluate.h"
#include "plslam/eval/kitti_metric.h"
#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam::bench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// A dataset that only has a ground truth (the scoring reads nothing else).
class GroundTruthOnly : public io::Dataset {
 public:
  explicit GroundTruthOnly(Trajectory gt, io::DatasetFormat format = io::DatasetFormat::kEuroc) : format_(format) {
    for (const auto& p : gt) timestamps_.push_back(p.t);
    gt_ = std::move(gt);
  }
  io::DatasetFormat format() const override { return format_; }
  io::StereoFrame load(std::size_t) const override { throw InputError("", "no images"); }

 private:
  io::DatasetFormat format_;
};

// A 5 m wavy path along x, 100 poses at 20 Hz, turning slowly.
Trajectory wavy_path() {
  Trajectory t;
  for (int i = 0; i < 100; ++i) {
    StampedPose p;
    p.t = 0.05 * i;
    p.T.linear() = Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.T.translation() = Eigen::Vector3d(0.05 * i, 0.2 * std::sin(0.1 * i), 0.01 * i);
    t.push_back(p);
  }
  return t;
}

void write_text(const fs::path& p, const std::string& s) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << s;
}

TEST(SlamBenchPlan, RunsAlternateRowsAndDatasetsBeforeTheNextRepetition) {
  const auto jobs = plan_jobs(2, 3, 2);
  ASSERT_EQ(jobs.size(), 12u);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(jobs[k].run, 1);
  for (std::size_t k = 6; k < 12; ++k) EXPECT_EQ(jobs[k].run, 2);
  EXPECT_EQ(jobs[0].row, 0u);
  EXPECT_EQ(jobs[1].row, 1u);
  EXPECT_EQ(jobs[2].row, 2u);
  EXPECT_EQ(jobs[3].dataset, 1u);
}

TEST(SlamBenchPlan, AnchorRowsFollowTheConfigurationsWithAnOdometryTwinWhenAsked) {
  const auto all = builtin_slam_configurations();
  auto rows = bench_rows(all, "anchor");
  ASSERT_EQ(rows.size(), all.size() + 2);
  EXPECT_TRUE(rows[all.size()].anchor);
  EXPECT_TRUE(rows[all.size()].loop_closing);
  EXPECT_EQ(rows.back().name, "anchor-no-loop-closing");
  EXPECT_FALSE(rows.back().loop_closing);
  EXPECT_FALSE(rows[5].loop_closing);  // no-loop-closing
  EXPECT_TRUE(rows[all.size() - 1].loop_closing);  // stereo
  EXPECT_TRUE(rows[0].loop_closing);
  rows = bench_rows(select_slam_configurations("full,no-lines", all), "anchor");
  EXPECT_EQ(rows.size(), 3u);
  EXPECT_EQ(bench_rows(all, "").size(), all.size());
}

TEST(SlamBenchPlan, DatasetNamesAreReadableAndUnique) {
  const auto d = name_datasets({"/data/kitti/sequences/06", "/data/euroc/V1_01_easy/mav0", "/a/office", "/b/office/"});
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0].name, "kitti-06");
  EXPECT_EQ(d[1].name, "V1_01_easy");
  EXPECT_EQ(d[2].name, "office");
  EXPECT_EQ(d[3].name, "office-2");
  // Rendered sequences keep the preset's names; a user's folder of the same name gets a suffix.
  const auto r = name_datasets({"/out/data/street-loop/sequences/00", "/x/street-loop"}, {"street-loop"});
  EXPECT_EQ(r[0].name, "street-loop");
  EXPECT_EQ(r[1].name, "street-loop-2");
}

TEST(SlamConfigurations, BuiltInsApplyToBothPresetsAndSelectionKeepsTheOrderGiven) {
  const auto all = builtin_slam_configurations();
  std::vector<std::string> names;
  for (const auto& c : all) {
    names.push_back(c.name);
    EXPECT_NO_THROW(validate_slam_configuration(c, "builtin"));
  }
  EXPECT_EQ(names, (std::vector<std::string>{"full", "no-lines", "quadtree", "no-pid", "no-kalman", "no-loop-closing",
                                             "stereo-inertial", "stereo"}));
  const auto sel = select_slam_configurations("no-pid,full", all);
  ASSERT_EQ(sel.size(), 2u);
  EXPECT_EQ(sel[0].name, "no-pid");
  EXPECT_EQ(select_slam_configurations("all", all).size(), all.size());
  EXPECT_THROW(select_slam_configurations("full,nolines", all), InputError);
  EXPECT_THROW(select_slam_configurations("full,full", all), InputError);
  EXPECT_THROW(select_slam_configurations("", all), InputError);
}

TEST(SlamConfigurations, AUserFileIsCheckedKeyByKeyAgainstThePresets) {
  test::TempDir dir;
  const auto good = dir.path() / "good.yaml";
  write_text(good, "configs:\n  dense-kf:\n    description: more keyframes\n    overrides: {keyframe: {ratio: 0.95}}\n"
                   "  plain:\n    overrides: {}\n");
  const auto c = load_slam_configurations(good);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_FALSE(disables_loop_closing(c[0]));
  const auto odo = parse_slam_configurations("configs:\n  odo:\n    overrides:\n      loop:\n        enabled: false\n", "t");
  ASSERT_EQ(odo.size(), 1u);
  EXPECT_TRUE(disables_loop_closing(odo[0]));
  EXPECT_EQ(bench_rows(odo, "anchor").back().name, "anchor-no-loop-closing");
  EXPECT_EQ(c[0].name, "dense-kf");
  EXPECT_EQ(c[0].description, "more keyframes");
  EXPECT_NE(c[0].yaml.find("ratio"), std::string::npos);

  const auto typo = dir.path() / "typo.yaml";
  write_text(typo, "configs:\n  x:\n    overrides: {keyframe: {ratoi: 0.9}}\n");
  try {
    load_slam_configurations(typo);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("typo.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ratoi"), std::string::npos) << e.what();
  }
  const auto bad_value = dir.path() / "bad_value.yaml";
  write_text(bad_value, "configs:\n  x:\n    overrides: {keyframe: {ratio: 3}}\n");
  EXPECT_THROW(load_slam_configurations(bad_value), InputError);
  const auto bad_name = dir.path() / "bad_name.yaml";
  write_text(bad_name, "configs:\n  ../x:\n    overrides: {}\n");
  EXPECT_THROW(load_slam_configurations(bad_name), InputError);
  const auto not_configs = dir.path() / "not.yaml";
  write_text(not_configs, "keyframe: {ratio: 0.9}\n");
  EXPECT_THROW(load_slam_configurations(not_configs), InputError);
  EXPECT_THROW(load_slam_configurations(dir.path() / "missing.yaml"), InputError);
}

TEST(SlamBenchScoring, ARunIsScoredLikePlslamEvalAndItsStatsAreRead) {
  test::TempDir dir;
  const Trajectory gt = wavy_path();
  GroundTruthOnly ds(gt);
  // The estimate: the ground truth in another frame (any SE(3)), with a wobble of known size.
  Trajectory est = gt;
  const Eigen::Isometry3d world = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  for (std::size_t i = 0; i < est.size(); ++i) {
    est[i].T = world * est[i].T;
    est[i].T.translation() += Eigen::Vector3d(0, 0, i % 2 ? 0.01 : -0.01);
  }
  const auto run = dir.path() / "run";
  io::write_trajectory(run / "trajectory.tum", est, io::TrajectoryFormat::kTum);
  write_text(run / "stats.json", R"({"input_frames": 100, "tracked_frames": 95, "lost_events": 1,
    "relocalizations": {"count": 1, "frames": [50]}, "loops": [{"frame": 90}], "keyframes": 12,
    "map_points": 3000, "map_lines": 400, "tracking_ms": {"median": 21.5, "p90": 30.0},
    "imu": {"slam": {"mode": "stereo-inertial", "imu_tracked_frames": 60}}})");
  const json m = measure_run(ds, run, false);
  const auto expected = eval::evaluate(gt, io::read_trajectory(run / "trajectory.tum", io::TrajectoryFormat::kTum), {});
  ASSERT_TRUE(m["ate_m"].is_number()) << m.dump();
  EXPECT_EQ(m["ate_m"].get<double>(), expected.ape_trans_stats.rmse);
  EXPECT_NEAR(m["ate_m"].get<double>(), 0.01, 0.002);
  EXPECT_EQ(m["rpe_frame_trans_m"].get<double>(), expected.rpe_trans_stats.rmse);
  EXPECT_NEAR(m["rpe_frame_trans_m"].get<double>(), 0.02, 1e-6);  // consecutive poses wobble by 2 x 0.01
  EXPECT_NEAR(m["rpe_frame_rot_deg"].get<double>(), 0.0, 1e-6);
  EXPECT_TRUE(m["rpe_1m_trans_m"].is_number());
  EXPECT_DOUBLE_EQ(m["tracked_share"].get<double>(), 0.95);
  EXPECT_DOUBLE_EQ(m["imu_share"].get<double>(), 0.6);
  EXPECT_EQ(m["lost_events"], 1);
  EXPECT_EQ(m["relocalizations"], 1);
  EXPECT_EQ(m["loops"], 1);
  EXPECT_EQ(m["keyframes"], 12);
  EXPECT_EQ(m["map_lines"], 400);
  EXPECT_DOUBLE_EQ(m["tracking_ms_median"].get<double>(), 21.5);
  EXPECT_FALSE(m.contains("error"));
}

// KITTI input: the devkit's t_rel and r_rel, on trajectory.kitti (one pose per input frame), as
// eval::kitti_odometry_metric gives them; none on EuRoC input or without the file.
TEST(SlamBenchScoring, KittiInputIsScoredWithTheDevkitsMetricOnTrajectoryKitti) {
  test::TempDir dir;
  Trajectory gt;  // 300 m straight at 10 Hz, 1 m a frame
  for (int i = 0; i <= 300; ++i) {
    StampedPose p;
    p.t = 0.1 * i;
    p.T.translation() = Eigen::Vector3d(0, 0, i);
    gt.push_back(p);
  }
  Trajectory est = gt;  // 1 % too long
  for (auto& p : est) p.T.translation() *= 1.01;
  const auto run = dir.path() / "run";
  io::write_trajectory(run / "trajectory.tum", est, io::TrajectoryFormat::kTum);
  io::write_trajectory(run / "trajectory.kitti", est, io::TrajectoryFormat::kKitti);
  write_text(run / "stats.json", R"({"input_frames": 301, "tracked_frames": 301})");
  const json m = measure_run(GroundTruthOnly(gt, io::DatasetFormat::kKitti), run, false);
  const auto expected = eval::kitti_odometry_metric(gt, est);
  ASSERT_TRUE(m["kitti_t_rel_percent"].is_number()) << m.dump();
  EXPECT_DOUBLE_EQ(m["kitti_t_rel_percent"].get<double>(), expected.t_rel_percent);
  EXPECT_NEAR(m["kitti_t_rel_percent"].get<double>(), 1.0, 0.02);  // the devkit divides by the nominal length
  EXPECT_NEAR(m["kitti_r_rel_deg_per_100m"].get<double>(), 0.0, 1e-9);
  EXPECT_TRUE(measure_run(GroundTruthOnly(gt), run, false)["kitti_t_rel_percent"].is_null());
  fs::remove(run / "trajectory.kitti");
  EXPECT_TRUE(measure_run(GroundTruthOnly(gt, io::DatasetFormat::kKitti), run, false)["kitti_t_rel_percent"].is_null());
}

TEST(SlamBenchScoring, AnAnchorsStatsAreReadFromItsOwnKeys) {
  test::TempDir dir;
  const Trajectory gt = wavy_path();
  GroundTruthOnly ds(gt);
  const auto run = dir.path() / "anchor";
  io::write_trajectory(run / "trajectory.tum", gt, io::TrajectoryFormat::kTum);
  write_text(run / "stats.json", R"({"frames": 100, "frames_tracked_ok": 80, "keyframes": 30, "map_points": 900,
    "loop_corrections": 2, "events": {"lost_transitions": 3, "relocalized": 1},
    "tracking_ms": {"median": 25.0, "mean": 26.0, "p90": 33.0}})");
  const json m = measure_run(ds, run, true);
  EXPECT_NEAR(m["ate_m"].get<double>(), 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(m["tracked_share"].get<double>(), 0.8);
  EXPECT_TRUE(m["imu_share"].is_null());
  EXPECT_EQ(m["lost_events"], 3);
  EXPECT_EQ(m["relocalizations"], 1);
  EXPECT_EQ(m["loops"], 2);
  EXPECT_TRUE(m["map_lines"].is_null());
  EXPECT_DOUBLE_EQ(m["tracking_ms_p90"].get<double>(), 33.0);
}

TEST(SlamBenchScoring, ARunWithoutOutputsSaysWhyAndScoresNothing) {
  test::TempDir dir;
  GroundTruthOnly ds(wavy_path());
  json m = measure_run(ds, dir.path() / "nothing", false);
  EXPECT_TRUE(m["ate_m"].is_null());
  EXPECT_NE(m["error"].get<std::string>().find("stats.json"), std::string::npos);
  write_text(dir.path() / "no_traj" / "stats.json", R"({"input_frames": 10, "tracked_frames": 0})");
  m = measure_run(ds, dir.path() / "no_traj", false);
  EXPECT_TRUE(m["ate_m"].is_null());
  EXPECT_NE(m["error"].get<std::string>().find("trajectory.tum"), std::string::npos);
  EXPECT_DOUBLE_EQ(m["tracked_share"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(m["imu_share"].get<double>(), 0.0);  // a plslam run without the IMU
}

TEST(SlamBenchSummary, MediansMinMaxAndRatiosUseSuccessfulRunsOnly) {
  const std::vector<BenchDataset> datasets = {{"d", "/d", {}, {}}};
  const auto configs = select_slam_configurations("full,no-lines,no-loop-closing", builtin_slam_configurations());
  const auto rows = bench_rows(configs, "anchor");
  json results = json::array();
  auto add = [&](const std::string& row, int run, int rc, double ate, double ms) {
    json m = json::object();
    for (const auto& k : bench_metrics()) m[k.key] = nullptr;
    m["ate_m"] = ate;
    m["tracking_ms_median"] = ms;
    results.push_back({{"dataset", "d"}, {"row", row}, {"run", run}, {"exit_code", rc}, {"metrics", m}});
  };
  add("full", 1, 0, 0.01, 20);
  add("full", 2, 0, 0.03, 22);
  add("full", 3, 0, 0.02, 21);
  add("no-lines", 1, 0, 0.04, 10);
  add("no-lines", 2, 0, 0.04, 10);
  add("no-lines", 3, 3, 9.0, 10);  // failed: not counted in the statistics
  add("no-loop-closing", 1, 0, 0.05, 20);
  add("anchor", 1, 0, 0.04, 42);
  add("anchor-no-loop-closing", 1, 0, 0.10, 40);
  const json s = summarize_runs(results, datasets, rows)["d"];
  EXPECT_DOUBLE_EQ(s["full"]["ate_m"]["median"].get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(s["full"]["ate_m"]["min"].get<double>(), 0.01);
  EXPECT_DOUBLE_EQ(s["full"]["ate_m"]["max"].get<double>(), 0.03);
  EXPECT_EQ(s["full"]["ate_m"]["n"], 3);
  EXPECT_EQ(s["no-lines"]["ate_m"]["n"], 2);
  EXPECT_EQ(s["no-lines"]["failed_runs"], 1);
  EXPECT_EQ(s["no-lines"]["runs"], 3);
  EXPECT_DOUBLE_EQ(s["no-lines"]["ratio_to_full"]["ate_m"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(s["no-lines"]["ratio_to_full"]["tracking_ms_median"].get<double>(), 10.0 / 21.0);
  EXPECT_FALSE(s["full"].contains("ratio_to_full"));
  EXPECT_EQ(s["full"]["ratio_to_anchor"]["anchor"], "anchor");
  EXPECT_DOUBLE_EQ(s["full"]["ratio_to_anchor"]["ate_m"].get<double>(), 0.5);
  EXPECT_EQ(s["no-loop-closing"]["ratio_to_anchor"]["anchor"], "anchor-no-loop-closing");
  EXPECT_DOUBLE_EQ(s["no-loop-closing"]["ratio_to_anchor"]["ate_m"].get<double>(), 0.5);
  EXPECT_TRUE(s["full"]["keyframes"].is_null());

  json report = {{"rows", json::array()}, {"datasets", json::array({{{"name", "d"}, {"path", "/d"}, {"frames", 3}, {"gt_length_m", 1.0}}})},
                 {"configurations", json::array()}, {"summary", {{"d", s}}}, {"interrupted_by", nullptr}};
  for (const auto& r : rows) report["rows"].push_back({{"name", r.name}, {"anchor", r.anchor}});
  const auto md = format_report_markdown(report);
  EXPECT_NE(md.find("| full | 0.0200 (0.0100–0.0300) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | 1 |"), std::string::npos) << md;  // no-lines: ATE / full, ATE / anchor
}

// The stereo-inertial row against the stereo one: ratios of the medians, and a line in the report.
TEST(SlamBenchSummary, StereoInertialIsComparedWithStereo) {
  const std::vector<BenchDataset> datasets = {{"d", "/d", {}, {}}};
  const auto rows = bench_rows(select_slam_configurations("stereo-inertial,stereo", builtin_slam_configurations()), "");
  json results = json::array();
  auto add = [&](const std::string& row, int run, double ate, double ms, double imu) {
    json m = json::object();
    for (const auto& k : bench_metrics()) m[k.key] = nullptr;
    m["ate_m"] = ate;
    m["tracking_ms_median"] = ms;
    m["imu_share"] = imu;
    results.push_back({{"dataset", "d"}, {"row", row}, {"run", run}, {"exit_code", 0}, {"metrics", m}});
  };
  add("stereo-inertial", 1, 0.006, 22, 0.8);
  add("stereo-inertial", 2, 0.004, 23, 0.8);
  add("stereo-inertial", 3, 0.005, 24, 0.8);
  add("stereo", 1, 0.010, 20, 0.0);
  add("stereo", 2, 0.008, 20, 0.0);
  add("stereo", 3, 0.009, 21, 0.0);
  const json s = summarize_runs(results, datasets, rows)["d"];
  EXPECT_DOUBLE_EQ(s["stereo-inertial"]["ratio_to_stereo"]["ate_m"].get<double>(), 0.005 / 0.009);
  EXPECT_DOUBLE_EQ(s["stereo-inertial"]["ratio_to_stereo"]["tracking_ms_median"].get<double>(), 23.0 / 20.0);
  EXPECT_FALSE(s["stereo"].contains("ratio_to_stereo"));
  EXPECT_FALSE(s["stereo-inertial"].contains("ratio_to_full"));  // no full row

  json report = {{"rows", json::array()}, {"datasets", json::array({{{"name", "d"}, {"path", "/d"}, {"frames", 3}}})},
                 {"configurations", json::array()}, {"summary", {{"d", s}}}, {"interrupted_by", nullptr}};
  for (const auto& r : rows) report["rows"].push_back({{"name", r.name}, {"anchor", r.anchor}});
  const auto md = format_report_markdown(report);
  EXPECT_NE(md.find("Stereo-inertial against stereo: ATE 0.0050 (0.0040–0.0060) m against 0.0090 (0.0080–0.0100) m "
                    "(0.556x), tracking 23.0 (22.0–24.0) ms against 20.0 (20.0–21.0) ms (1.15x); the IMU helped to "
                    "track 80.0 % of the frames."),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| stereo-inertial |"), std::string::npos) << md;
}

TEST(SlamBenchFigures, FrameTimesComeFromFramesCsvOrTheAnchorsList) {
  test::TempDir dir;
  write_text(dir.path() / "p" / "frames.csv", "frame,state,tracking_ms\n0,OK,12.5\n1,OK,13\n");
  EXPECT_EQ(read_frame_times(dir.path() / "p"), (std::vector<double>{12.5, 13.0}));
  write_text(dir.path() / "a" / "frame_times_ms.txt", "25.7\n28.1\n");
  EXPECT_EQ(read_frame_times(dir.path() / "a"), (std::vector<double>{25.7, 28.1}));
  EXPECT_TRUE(read_frame_times(dir.path() / "none").empty());
}

}  // namespace
}  // namespace plslam::bench
