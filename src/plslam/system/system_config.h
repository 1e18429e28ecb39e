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
//   place:    {enabled, vocabulary (relative to the config file)}
//   relocalization: {enabled, max_candidates, min_bow_matches, min_inliers, search_radius,
//              new_segment_after_s}
//   system:   {seed}
#include <filesystem>
#include <memory>
#include <optional>

#include "plslam/core/config_reader.h"
#include "plslam/place/vocabulary.h"
#include "plslam/system/slam_system.h"

namespace plslam::system {

// Applies `config` on top of `preset`, validates, and fails on unknown keys.
SystemOptions apply_config(const ConfigReader& config, SystemOptions preset);

// The vocabulary plslam ships (data/vocabulary/, see README: place recognition).
std::filesystem::path default_vocabulary_path();
// The vocabulary the options ask for (null with place recognition off); InputError naming the
// file when it is missing, truncated or not a vocabulary.
std::shared_ptr<const place::Vocabulary> load_vocabulary(const SystemOptions& options);

// The preset for a dataset format, overridden by the file when given.
SystemOptions load_system_options(io::DatasetFormat format, const std::optional<std::filesystem::path>& file);

}  // namespace plslam::system
