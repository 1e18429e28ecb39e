#pragma once
// The figures of `plslam bench slam`, drawn with the eval library's Chart: per dataset, the
// trajectories against the ground truth (top view aligned, top view aligned at the first pose
// only, and an oblique 3D view), translation error over time and rotation drift since the first
// pose (free of the alignment), and per-frame tracking time; over all datasets, the keyframe
// counts as grouped bars.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plslam/bench/slam_bench.h"
#include "plslam/core/types.h"
#include "plslam/eval/evaluate.h"

namespace plslam::bench {

// One row's representative run (the one with the median ATE) on one dataset.
struct FigureRun {
  std::string row;
  Trajectory estimate;         // as the run wrote it
  eval::EvalResult result;     // SE(3)-aligned against the ground truth
  std::vector<double> frame_ms;  // tracking time per frame
};

// Per-frame tracking times of a run folder: frames.csv's tracking_ms (plslam) or
// frame_times_ms.txt (anchor); empty when neither is there.
std::vector<double> read_frame_times(const std::filesystem::path& folder);

// Writes <dataset>_trajectory.png, <dataset>_trajectory_first_pose.png, <dataset>_trajectory_3d.png,
// <dataset>_errors.png and <dataset>_tracking_ms.png into `dir`; returns the file names written.
std::vector<std::string> write_dataset_figures(const std::filesystem::path& dir, const std::string& dataset,
                                               const Trajectory& ground_truth, const std::vector<FigureRun>& runs);

// keyframes.png: median keyframes per dataset (groups) and row (bars). Returns the file name.
std::string write_keyframe_bars(const std::filesystem::path& dir, const nlohmann::json& summary,
                                const std::vector<BenchDataset>& datasets, const std::vector<BenchRow>& rows);

}  // namespace plslam::bench
