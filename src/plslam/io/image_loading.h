#pragma once
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

namespace plslam::io {

// Decodes an 8-bit grey image. A missing, unreadable, truncated or empty file throws InputError
// naming the file, never returns an empty Mat.
cv::Mat load_grey_image(const std::filesystem::path& path);

// "<path>: blank image (every pixel is V)" when every pixel has the same value, else empty: a
// dead sensor or a zero-filled file decodes fine but carries no features, and tracking it would
// declare the camera lost. Checked on the decoded image, before rectification blends in borders.
std::string blank_image_problem(const cv::Mat& image, const std::filesystem::path& path);

}  // namespace plslam::io
