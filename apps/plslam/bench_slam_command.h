#pragma once
// `plslam bench slam`: the paper's experiments as one command (see bench/slam_bench.h).
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands/mode_options.h"

namespace plslam::cli {

struct BenchSlamArgs {
  std::vector<std::string> datasets;
  std::string out;
  int runs = 3;
  std::string configs = "all";
  std::string config_file;
  std::string anchor;
  std::string preset;  // "", quick or paper
  std::string shared;  // ../shared for --preset paper
  int jobs = 1;
  ModeArgs mode;
  int table1_frames = 20;
  bool json = false;
  // Standard suites by their official folder names (bench/dataset_suites.h).
  std::string euroc_root, kitti_root, tumvi_root;
  std::string plan;                      // write the matrix as shell commands instead of running it
  std::vector<std::string> report_from;  // build the report from these folders' runs
  bool resume = false;                   // skip the runs already complete
};

// Exit code when some runs failed (the report is still written and marks them).
constexpr int kExitRunsFailed = 4;

void add_bench_slam_options(CLI::App& sub, BenchSlamArgs& args);
int run_bench_slam(const BenchSlamArgs& args);

}  // namespace plslam::cli
