// `plslam bench slam` through the real binary: the quick preset's report against separate
// `plslam run` + `plslam eval` calls, an anchor row, interruption and bad input.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "plslam/bench/slam_bench.h"
#include "support/test_support.h"

namespace plslam::bench {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test::run_cli;

std::string q(const fs::path& p) {
  std::string s(1, '\'');
  s.append(p.string());
  s.push_back('\'');
  return s;
}

json read_json(const fs::path& p) { return json::parse(test::read_file(p)); }

// ATE by `plslam eval` against the ground truth the dataset reader uses (the body poses moved
// to the left camera), as the bench and `plslam run` score.
double eval_ate(const fs::path& dataset, const fs::path& est) {
  const auto r = run_cli("eval --gt " + q(dataset / "mav0" / "state_groundtruth_estimate0" / "data.csv") +
                         " --gt-body-to-cam " + q(dataset / "mav0" / "cam0" / "sensor.yaml") + " --est " + q(est) +
                         " --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return json::parse(r.out)["ape_trans_m"]["rmse"].get<double>();
}

// A short rendered office sequence of its own for each test (ctest runs every test in a process).
fs::path render_office(const fs::path& dir, int frames) {
  const auto out = dir / "office";
  const auto r = run_cli("synth --scene office --preset euroc --frames " + std::to_string(frames) +
                         " --seed 11 --out " + q(out));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return out;
}

// The quick preset, sequential: every configuration and metric is in the report, and each
// number equals that of a separate `plslam run --sequential` + `plslam eval`.
TEST(BenchSlamCli, QuickPresetReportsEveryConfigurationAndMetricAsSeparateSequentialRunsDo) {
  test::TempDir dir;
  const auto seq = dir.path() / "seq";
  const auto r = run_cli("bench slam --preset quick --runs 1 --sequential --table1-frames 3 --json --out " + q(seq));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);  // stdout is only the JSON
  EXPECT_EQ(read_json(seq / "report.json"), report);
  std::vector<std::string> names;
  for (const auto& c : report["configurations"]) names.push_back(c["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"full", "no-lines", "quadtree", "no-pid", "no-kalman", "no-loop-closing",
                                             "stereo-inertial", "stereo"}));
  ASSERT_EQ(report["datasets"].size(), 1u);
  const json& s = report["summary"]["office-quick"];
  for (const auto& name : names) {
    for (const auto& k : bench_metrics()) {
      if (name == "no-lines" && std::string(k.key) == "map_lines") continue;  // 0 lines: still a number
      ASSERT_TRUE(s[name][k.key].is_object()) << name << " " << k.key;
      EXPECT_EQ(s[name][k.key]["n"], 1) << name << " " << k.key;
    }
    EXPECT_EQ(s[name]["failed_runs"], 0);
  }
  EXPECT_DOUBLE_EQ(s["full"]["tracked_share"]["median"].get<double>(), 1.0);
  EXPECT_EQ(s["no-lines"]["map_lines"]["median"].get<double>(), 0.0);
  EXPECT_GT(s["full"]["map_lines"]["median"].get<double>(), 0.0);
  EXPECT_LT(s["full"]["ate_m"]["median"].get<double>(), 0.02);
  EXPECT_TRUE(s["no-lines"]["ratio_to_full"]["ate_m"].is_number());
  EXPECT_TRUE(s["stereo-inertial"]["ratio_to_stereo"]["ate_m"].is_number());
  EXPECT_EQ(s["stereo"]["imu_share"]["median"].get<double>(), 0.0);
  // Table I and the figures exist and are named in the report.
  const json& t1 = report["table1"]["office-quick"];
  EXPECT_GT(t1["quadtree_ms"].get<double>(), 0.0);
  EXPECT_GT(t1["ssc_speedup"].get<double>(), 0.0);
  int figures = 0;
  for (const auto& [key, list] : report["figures"].items()) {
    for (const auto& f : list) {
      EXPECT_TRUE(fs::exists(seq / f.get<std::string>())) << f;
      ++figures;
    }
  }
  EXPECT_EQ(figures, 6);
  const auto md = test::read_file(seq / "report.md");
  for (const auto& name : names) EXPECT_NE(md.find("| " + name + " |"), std::string::npos) << name;
  EXPECT_NE(md.find("Table I"), std::string::npos);
  EXPECT_NE(md.find("Stereo-inertial against stereo: "), std::string::npos);
  EXPECT_NE(report["command"].get<std::string>().find("--preset quick --runs 1 --sequential --table1-frames 3 --out "),
            std::string::npos)
      << report["command"];

  const auto dataset = seq / "data" / "office-quick";
  for (const std::string config : {"full", "no-lines"}) {
    const auto out = dir.path() / ("separate-" + config);
    const auto rr = run_cli("run " + q(dataset) + " --sequential --quiet --config " +
                            q(seq / "configs" / (config + ".yaml")) + " --out " + q(out));
    ASSERT_EQ(rr.exit_code, 0) << rr.err;
    EXPECT_EQ(test::read_file(out / "trajectory.tum"),
              test::read_file(seq / "runs" / "office-quick" / config / "run-1" / "trajectory.tum"))
        << config;
    const double ate = eval_ate(dataset, out / "trajectory.tum");
    EXPECT_EQ(report["summary"]["office-quick"][config]["ate_m"]["median"].get<double>(), ate) << config;
  }
}

TEST(BenchSlamCli, DefaultRunsEqualASeparateRunAndAnAnchorIsARow) {
  test::TempDir dir;
  const auto dataset = render_office(dir.path(), 40);
  // A stand-in anchor with the runner's interface: the ground truth with a 1 cm wobble.
  const auto anchor = dir.path() / "anchor.sh";
  std::ofstream(anchor) << "#!/bin/sh\n"
                           "set -e\n"
                           "ds=$1; out=$3; mkdir -p \"$out\"\n"
                           "awk 'NR%2==0 && !/^#/ {$2=$2+0.01} {print}' \"$ds/mav0/synth/left_camera.tum\" > "
                           "\"$out/trajectory.tum\"\n"
                           "n=$(grep -vc '^#' \"$ds/mav0/synth/left_camera.tum\")\n"
                           "echo \"{\\\"frames\\\": $n, \\\"frames_tracked_ok\\\": $n, \\\"keyframes\\\": 7, "
                           "\\\"map_points\\\": 100, \\\"loop_corrections\\\": 0, \\\"events\\\": {\\\"lost_transitions\\\": 0, "
                           "\\\"relocalized\\\": 0}, \\\"tracking_ms\\\": {\\\"median\\\": 30, \\\"p90\\\": 40}}\" > \"$out/stats.json\"\n";
  ::chmod(anchor.c_str(), 0755);
  const auto out = dir.path() / "conc";
  const auto r = run_cli("bench slam " + q(dataset) + " --configs full --runs 3 --table1-frames 0 --anchor " + q(anchor) +
                         " --out " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json rep = read_json(out / "report.json");
  const json& s = rep["summary"]["office"];
  ASSERT_TRUE(s["anchor"]["ate_m"].is_object()) << s.dump();
  EXPECT_NEAR(s["anchor"]["ate_m"]["median"].get<double>(), 0.005, 0.002);
  EXPECT_EQ(s["anchor"]["keyframes"]["median"], 7);
  EXPECT_TRUE(s["full"]["ratio_to_anchor"]["ate_m"].is_number());
  EXPECT_FALSE(s.contains("anchor-no-loop-closing"));
  // The default mode is deterministic: the bench's runs and a separate run agree to the byte.
  EXPECT_EQ(s["full"]["ate_m"]["min"], s["full"]["ate_m"]["max"]);
  const auto sep = dir.path() / "separate";
  const auto rr = run_cli("run " + q(dataset) + " --quiet --config " + q(out / "configs" / "full.yaml") + " --out " +
                          q(sep));
  ASSERT_EQ(rr.exit_code, 0) << rr.err;
  EXPECT_EQ(test::read_file(sep / "trajectory.tum"),
            test::read_file(out / "runs" / "office" / "full" / "run-2" / "trajectory.tum"));
  EXPECT_EQ(eval_ate(dataset, sep / "trajectory.tum"), s["full"]["ate_m"]["median"].get<double>());
}

TEST(BenchSlamCli, SigtermStopsAtARunBoundaryAndTheReportCoversTheRunsDone) {
  test::TempDir dir;
  const auto dataset = render_office(dir.path(), 40);
  const auto out = dir.path() / "stopped";
  const auto r = run_cli("bench slam " + q(dataset) + " --runs 5 --table1-frames 0 --out " + q(out) +
                         " & pid=$!; sleep 4; kill -TERM $pid; wait $pid");
  EXPECT_EQ(r.exit_code, 143) << r.err;
  ASSERT_TRUE(fs::exists(out / "report.json")) << r.err;
  const json rep = read_json(out / "report.json");
  EXPECT_EQ(rep["interrupted_by"], "SIGTERM");
  EXPECT_LT(rep["results"].size(), 30u);
  EXPECT_GE(rep["results"].size(), 1u);
  EXPECT_NE(test::read_file(out / "report.md").find("interrupted by SIGTERM"), std::string::npos);
}

TEST(BenchSlamCliInput, BadInputFailsBeforeAnyRunWithOneLineNamingIt) {
  test::TempDir dir;
  auto r = run_cli("bench slam --preset quick --configs full,nolines --out " + q(dir.path() / "a"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("nolines"), std::string::npos) << r.err;
  r = run_cli("bench slam --preset quick --anchor /nonexistent/run --out " + q(dir.path() / "b"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent/run"), std::string::npos) << r.err;
  r = run_cli("bench slam --out " + q(dir.path() / "c"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no dataset"), std::string::npos) << r.err;
  fs::create_directories(dir.path() / "d" / "runs");
  r = run_cli("bench slam --preset quick --out " + q(dir.path() / "d"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("earlier bench"), std::string::npos) << r.err;
  r = run_cli("bench slam " + q(dir.path() / "nowhere") + " --out " + q(dir.path() / "e"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.path() / "a" / "runs"));
}

}  // namespace
}  // namespace plslam::bench
