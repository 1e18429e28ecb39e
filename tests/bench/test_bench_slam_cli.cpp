// `plslam bench slam` through the real binary: the quick preset's report against separate
// `plslam run` + `plslam eval` calls, an anchor row, interruption and bad input.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>

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
      if (std::string(k.key).rfind("kitti_", 0) == 0) {
        EXPECT_TRUE(s[name][k.key].is_null()) << "the KITTI devkit's metric on EuRoC input";
        continue;
      }
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

// The numbers of a summary that do not depend on the machine's speed.
json without_timing(json summary) {
  for (auto& [dataset, rows] : summary.items()) {
    for (auto& [row, s] : rows.items()) {
      s.erase("tracking_ms_median");
      s.erase("tracking_ms_p90");
      for (const char* r : {"ratio_to_full", "ratio_to_anchor", "ratio_to_stereo"}) {
        if (s.contains(r)) s[r].erase("tracking_ms_median");
      }
    }
  }
  return summary;
}

int shell_exit(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The same matrix run by the bench itself and as a plan through GNU parallel (two job slots on this
// host), then --report-from: the same report, timings aside (the default mode is deterministic).
// Then what --report-from checks: a run from another host makes timings not comparable, a missing
// run is named, a run of another build is refused; and --resume runs only what is not complete.
TEST(BenchSlamCli, APlanRunThroughGnuParallelReportsAsTheBenchItselfDoes) {
  ASSERT_EQ(shell_exit("command -v parallel > /dev/null"), 0) << "GNU parallel is missing (scripts/install-deps.sh installs it)";
  test::TempDir dir;
  const auto dataset = render_office(dir.path(), 40);
  const std::string matrix = "bench slam " + q(dataset) + " --configs full,no-lines --runs 1 --table1-frames 0";
  const auto direct = dir.path() / "direct";
  auto r = run_cli(matrix + " --json --out " + q(direct));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json expected = json::parse(r.out);

  const auto planned = dir.path() / "planned";
  const auto plan = dir.path() / "plan.txt";
  r = run_cli(matrix + " --plan " + q(plan) + " --json --out " + q(planned));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["runs"], 2);
  EXPECT_FALSE(fs::exists(planned / "runs"));  // nothing ran
  EXPECT_EQ(shell_exit("bash -n " + q(plan.string() + ".sbatch")), 0);
  ASSERT_EQ(shell_exit("parallel --will-cite --sshlogin 2/: --joblog " + q(dir.path() / "joblog") + " < " + q(plan)), 0)
      << test::read_file(dir.path() / "joblog");
  r = run_cli("bench slam --report-from " + q(planned) + " --json --out " + q(planned));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json report = json::parse(r.out);
  EXPECT_EQ(without_timing(report["summary"]), without_timing(expected["summary"]));
  ASSERT_EQ(report["results"].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(report["results"][k]["row"], expected["results"][k]["row"]);
    EXPECT_EQ(report["results"][k]["metrics"]["ate_m"], expected["results"][k]["metrics"]["ate_m"]);
  }
  EXPECT_TRUE(report["missing_runs"].empty());
  EXPECT_EQ(report["timing"]["comparable"], true);
  EXPECT_EQ(report["runs_build_id"], expected["build_id"]);

  // Runs collected from two hosts (an exit file edited as another node would have written it).
  const auto no_lines = planned / "runs" / "office" / "no-lines" / "run-1";
  std::ofstream(no_lines.string() + ".exit") << "0 node7\n";
  r = run_cli("bench slam --report-from " + q(planned) + " --out " + q(dir.path() / "hosts"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(dir.path() / "hosts" / "report.json")["timing"]["comparable"], false);
  EXPECT_NE(test::read_file(dir.path() / "hosts" / "report.md").find("Timings are not comparable"), std::string::npos);
  // A missing run is named; the report covers the others.
  fs::rename(no_lines.string() + ".exit", dir.path() / "kept.exit");
  r = run_cli("bench slam --report-from " + q(planned) + " --out " + q(dir.path() / "missing"));
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("office/no-lines/run-1"), std::string::npos) << r.err;
  EXPECT_EQ(read_json(dir.path() / "missing" / "report.json")["missing_runs"], json::array({"office/no-lines/run-1"}));
  // ... and found in a second folder of collected runs.
  const auto elsewhere = dir.path() / "node7" / "runs" / "office" / "no-lines";
  fs::create_directories(elsewhere);
  fs::rename(no_lines, elsewhere / "run-1");
  fs::rename(dir.path() / "kept.exit", elsewhere / "run-1.exit");
  r = run_cli("bench slam --report-from " + q(planned) + " " + q(dir.path() / "node7") + " --out " + q(dir.path() / "two"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(without_timing(read_json(dir.path() / "two" / "report.json")["summary"]), without_timing(expected["summary"]));
  // A run of another build is refused, naming it.
  const auto stats_file = planned / "runs" / "office" / "full" / "run-1" / "stats.json";
  json stats = read_json(stats_file);
  stats["build"]["build_id"] = "0123";
  std::ofstream(stats_file) << stats.dump();
  r = run_cli("bench slam --report-from " + q(planned) + " " + q(dir.path() / "node7") + " --out " + q(dir.path() / "builds"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(stats_file.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("different builds"), std::string::npos) << r.err;

  // --resume keeps the complete runs and runs the one whose exit file is gone; a plan written again
  // leaves the complete runs out.
  fs::remove(direct / "runs" / "office" / "no-lines" / "run-1.exit");
  r = run_cli(matrix + " --resume --json --out " + q(direct));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("(1 complete, kept)"), std::string::npos) << r.err;
  EXPECT_EQ(without_timing(json::parse(r.out)["summary"]), without_timing(expected["summary"]));
  r = run_cli(matrix + " --plan " + q(plan) + " --resume --json --out " + q(direct));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["runs"], 0);
  EXPECT_EQ(test::read_file(plan), "");
  // Another matrix in the same folder is refused.
  r = run_cli("bench slam " + q(dataset) + " --configs full --runs 1 --resume --out " + q(direct));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("another matrix"), std::string::npos) << r.err;
}

// Fake roots of the official folder names, from the real excerpts and a render (as a TUM-VI room:
// its ground truth as mocap0): every present sequence is in the plan, every missing one named.
TEST(BenchSlamCli, SuitesByTheirRootsAreFoundAndTheMissingNamed) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir dir;
  const auto office = render_office(dir.path(), 20);
  const fs::path euroc = dir.path() / "euroc", tumvi = dir.path() / "tumvi";
  fs::create_directories(euroc);
  fs::create_directory_symlink(data / "euroc/V1_01_easy_micro", euroc / "V1_01_easy");
  const fs::path room = tumvi / "dataset-room4_512_16" / "mav0";
  fs::create_directories(room / "mocap0");
  for (const char* s : {"cam0", "cam1"}) fs::create_directory_symlink(office / "mav0" / s, room / s);
  fs::copy_file(office / "mav0" / "state_groundtruth_estimate0" / "data.csv", room / "mocap0" / "data.csv");
  const auto out = dir.path() / "out";
  const auto r = run_cli("bench slam --euroc-root " + q(euroc) + " --kitti-root " + q(data / "kitti") + " --tumvi-root " +
                         q(tumvi) + " --configs full --runs 2 --plan " + q(dir.path() / "plan.txt") + " --json --out " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["runs"], 2 * 4);
  const json plan = read_json(out / "plan.json")["matrix"];
  std::vector<std::string> names, ids;
  for (const auto& d : plan["datasets"]) {
    names.push_back(d["name"]);
    ids.push_back(d["sequence_id"]);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"V1_01_easy", "kitti-01", "kitti-06", "room4"}));
  EXPECT_EQ(ids, (std::vector<std::string>{"euroc/V101", "kitti/01", "kitti/06", "tumvi/room4"}));
  EXPECT_EQ(plan["missing_sequences"].size(), 10u + 9u + 5u);
  EXPECT_NE(r.err.find("missing: EuRoC MH_01_easy"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing: KITTI 00"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing: TUM-VI dataset-room1_512_16"), std::string::npos) << r.err;
  const std::string lines = test::read_file(dir.path() / "plan.txt");
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 8);
  EXPECT_NE(lines.find(q(euroc / "V1_01_easy")), std::string::npos);
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
