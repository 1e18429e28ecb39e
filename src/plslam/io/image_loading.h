#pragma once
#include <filesystem>

#include <opencv2/core.hpp>

namespace plslam::io {

// Decodes an 8-bit grey image. A missing, unreadable, truncated or empty file throws InputError
// naming the file, never returns an empty Mat.
cv::Mat load_grey_image(const std::filesystem::path& path);

}  // namespace plslam::io
