#pragma once
// The YAML configuration of `plslam run`: one section per module, defaults in code (the preset
// for the dataset), unknown keys rejected with their name.
//
//   features: {n_points, levels, scale_factor, fast_threshold, distribution: ssc|quadtree}
//   lines:    {enabled, max_lines}
//   tracking: {init_min_points, close_depth_baselines, motion_radius, local_map_radius,
//              line_radius, min_local_inliers}
//   keyframe: {ratio, max_frames, pid, pid_kp, pid_ki, pid_kd, pid_output_limit, kalman, max_speed,
//              velocity_min_frames}
//   optim:    {line_information}
//   mapping:  {local_ba, ba_iterations, culling_redundancy}
//   system:   {seed}
#include <filesystem>
#include <optional>

#include "plslam/core/config_reader.h"
#include "plslam/system/slam_system.h"

namespace plslam::system {

// Applies `config` on top of `preset`, validates, and fails on unknown keys.
SystemOptions apply_config(const ConfigReader& config, SystemOptions preset);

// The preset for a dataset format, overridden by the file when given.
SystemOptions load_system_options(io::DatasetFormat format, const std::optional<std::filesystem::path>& file);

}  // namespace plslam::system
