#pragma once
// Placeholder until the video branch lands its calibration file reader (same interface).
#include <filesystem>

#include "plslam/core/types.h"

namespace plslam::io {
StereoCalibration read_calibration_file(const std::filesystem::path& path);
}  // namespace plslam::io
