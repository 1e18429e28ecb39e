#pragma once
// PNG plots of an evaluation: trajectory top view, APE over time and RPE over time.
#include <filesystem>
#include <vector>

#include "plslam/eval/evaluate.h"

namespace plslam::eval {

struct PlotOptions {
  bool x_is_frame = false;  // the poses carry frame indices, not seconds (KITTI files)
};

// The two axes of the top view: the ones along which the ground truth extends most (the dropped
// axis is the vertical one: z for EuRoC/TUM worlds, y for KITTI camera frames).
std::pair<int, int> top_view_axes(const Trajectory& gt);

// Writes trajectory.png, ape.png and rpe.png into `dir` (created when missing) and returns their
// paths. Throws InputError when a file cannot be written.
std::vector<std::filesystem::path> write_plots(const EvalResult& r, const std::filesystem::path& dir,
                                               const PlotOptions& options = {});

}  // namespace plslam::eval
