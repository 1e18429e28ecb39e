#pragma once
// `plslam bench slam`: every (dataset, configuration) runs N times, each run in its own process,
// runs interleaved across configurations so that machine noise spreads evenly; then each run is
// scored against the ground truth and the runs are summarised (median, min, max) into
// report.json and report.md. The runner that starts the processes lives in the app; this is the
// plan, the scoring and the report.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plslam/bench/slam_configurations.h"
#include "plslam/io/dataset.h"

namespace plslam::bench {

// One row of the tables: a plslam configuration, or the external anchor (with or without its
// loop closing).
struct BenchRow {
  std::string name;
  bool anchor = false;
  bool loop_closing = true;  // plslam rows: read from the applied configuration
  SlamConfiguration config;  // plslam rows only
};

struct BenchDataset {
  std::string name;  // unique, used as a folder name
  std::filesystem::path path;
  std::filesystem::path calibration;  // `plslam run --calib`, where the folder has no sensor.yaml (TUM-VI)
  std::string sequence_id;            // a standard sequence (euroc/MH01, kitti/06): its published figures
};

struct BenchJob {
  std::size_t dataset = 0;
  std::size_t row = 0;
  int run = 1;  // 1-based
};

// The rows: the configurations, then, with an anchor, "anchor" (its loop closing on) and, when a
// configuration switches loop closing off, "anchor-no-loop-closing".
std::vector<BenchRow> bench_rows(const std::vector<SlamConfiguration>& configs, const std::string& anchor_name);

// Run 1 of every dataset and row, then run 2, ...: the rows alternate run by run.
std::vector<BenchJob> plan_jobs(std::size_t datasets, std::size_t rows, int runs);

// Unique names for dataset folders: preferred[i] when given and not empty, else the folder's
// name ("kitti-06" for a KITTI sequences/06); a numeric suffix on a clash.
std::vector<BenchDataset> name_datasets(const std::vector<std::filesystem::path>& paths,
                                        const std::vector<std::string>& preferred = {});

// The folder of one run: OUT/runs/<dataset>/<row>/run-<n>.
std::filesystem::path run_folder(const std::filesystem::path& out, const BenchDataset& d, const BenchRow& r, int run);

// A JSON file (stats.json, plan.json); InputError naming it when it is missing or not JSON.
nlohmann::json read_json_file(const std::filesystem::path& p);

// Scores one finished run folder (trajectory.tum, stats.json; frames.csv or frame_times_ms.txt)
// against the dataset's ground truth: ate_m, rpe_frame_trans_m, rpe_frame_rot_deg, rpe_1m_trans_m,
// rpe_1m_rot_deg, kitti_t_rel_percent and kitti_r_rel_deg_per_100m (KITTI input: the devkit's metric
// on trajectory.kitti, one pose per input frame), tracked_share, imu_share (plslam: frames tracked with the IMU), lost_events, relocalizations, loops, keyframes, map_points,
// map_lines, tracking_ms_median, tracking_ms_p90. A value the run does not provide is null;
// "error" says why a run has no score.
nlohmann::json measure_run(const io::Dataset& dataset, const std::filesystem::path& folder, bool anchor);

// Metric keys in report order, with their column label in report.md and decimals.
struct MetricInfo {
  const char* key;
  const char* label;
  int decimals;
};
const std::vector<MetricInfo>& bench_metrics();

// From the per-run results ({dataset, row, run, exit_code, metrics}) to
// summary[dataset][row][metric] = {median, min, max, n}, plus ratio_to_full and ratio_to_anchor
// (medians of ATE and of tracking ms) where those rows exist, and ratio_to_stereo on the
// stereo-inertial row when a stereo row exists.
nlohmann::json summarize_runs(const nlohmann::json& results, const std::vector<BenchDataset>& datasets,
                              const std::vector<BenchRow>& rows);

// The first metrics, up to kitti_r_rel_deg_per_100m, are accuracy; the rest behaviour and cost.
constexpr std::size_t kAccuracyMetrics = 7;

// report.md from report.json.
std::string format_report_markdown(const nlohmann::json& report);

}  // namespace plslam::bench
