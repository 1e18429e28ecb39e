#pragma once
// Trajectory files in the three formats SLAM users exchange:
//   TUM:   "t x y z qx qy qz qw" per line, t in seconds, '#' comments
//   KITTI: 12 numbers per line, the 3x4 row-major [R|t]; no timestamps (index = frame)
//   EuRoC: ASL csv, "t_ns, px, py, pz, qw, qx, qy, qz[, ...]" with a '#' header; extra columns ignored
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "plslam/core/types.h"

namespace plslam::io {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

// KITTI files hold rotation blocks with 6-9 digits. kNearestRotation projects each onto SO(3);
// kAsWritten keeps the 3x3 block as read, which is what evo and the KITTI devkit evaluate (their
// numbers differ in the 5th digit otherwise).
enum class KittiRotation { kNearestRotation, kAsWritten };

const char* to_string(TrajectoryFormat f);
// Parses "tum", "kitti", "euroc"; throws InputError otherwise.
TrajectoryFormat parse_trajectory_format(const std::string& name);

// Guesses the format from the extension (.csv -> euroc, .kitti -> kitti, .tum -> tum) and, when
// that does not decide, from the column count of the first data line (8 -> tum, 12 -> kitti,
// commas -> euroc). Throws InputError when it cannot tell.
TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path);

// Reads a trajectory. KITTI files have no times: `kitti_times` supplies them when given (same
// length required), otherwise frame i gets t = i. Any malformed line, wrong column count, NaN or
// decreasing timestamp throws InputError naming the file and line (equal stamps are accepted).
Trajectory read_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                           const std::vector<double>* kitti_times = nullptr,
                           KittiRotation kitti_rotation = KittiRotation::kNearestRotation);

// Writes with full double precision, so reading the file back gives the same poses to 1e-9.
void write_trajectory(const std::filesystem::path& path, const Trajectory& trajectory,
                      TrajectoryFormat format);

}  // namespace plslam::io
