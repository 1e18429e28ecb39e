#pragma once
// PNG plots of an evaluation: trajectory top view, APE over time and RPE over time.
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/eval/evaluate.h"
#include "plslam/eval/frame_log.h"

namespace plslam::eval {

struct PlotOptions {
  bool x_is_frame = false;  // the poses carry frame indices, not seconds (KITTI files)
};

// Encodes `img` as PNG and writes it whole or not at all (InputError naming `path`).
void save_png(const cv::Mat& img, const std::filesystem::path& path);

// The two axes of the top view: the ones along which the ground truth extends most (the dropped
// axis is the vertical one: z for EuRoC/TUM worlds, y for KITTI camera frames).
std::pair<int, int> top_view_axes(const Trajectory& gt);

// Writes trajectory.png, ape.png and rpe.png into `dir` (created when missing) and returns their
// paths. Throws InputError when a file cannot be written.
std::vector<std::filesystem::path> write_plots(const EvalResult& r, const std::filesystem::path& dir,
                                               const PlotOptions& options = {});

// tracking.png: three panels over the same time axis, to see where and why the error grows.
// APE with the keyframes marked; tracked point and line inliers against the keyframe rule's
// threshold; the local map's size and the close stereo points tracked. Returns the path written.
std::filesystem::path write_tracking_plot(const EvalResult& r, const FrameLog& log, const std::filesystem::path& dir,
                                          const PlotOptions& options = {});

// resources.png, for long runs: tracking ms per frame with its running median over `window`
// frames, the resident memory, and the map's keyframes, points / 100 and lines / 10, over the
// frame index.
// Needs frames.csv's map_* and rss_mb columns (InputError naming the file otherwise). Returns the
// path written.
std::filesystem::path write_resources_plot(const FrameLog& log, const std::filesystem::path& dir, int window = 101);

// Whether `log` has the columns write_resources_plot() needs (frames.csv of runs before they
// existed does not).
bool has_resource_columns(const FrameLog& log);

}  // namespace plslam::eval
