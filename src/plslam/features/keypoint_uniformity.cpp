#include "plslam/features/keypoint_uniformity.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plslam::features {

double grid_count_cv(const std::vector<cv::KeyPoint>& keypoints, cv::Size image_size, int cols, int rows) {
  if (cols < 1 || rows < 1 || image_size.width < 1 || image_size.height < 1)
    throw std::invalid_argument("grid_count_cv: empty grid or image");
  std::vector<int> counts(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows), 0);
  for (const auto& k : keypoints) {
    const int cx = std::clamp(static_cast<int>(k.pt.x * static_cast<float>(cols) / static_cast<float>(image_size.width)), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(k.pt.y * static_cast<float>(rows) / static_cast<float>(image_size.height)), 0, rows - 1);
    ++counts[static_cast<std::size_t>(cy * cols + cx)];
  }
  double mean = 0, var = 0;
  for (int c : counts) mean += c;
  mean /= static_cast<double>(counts.size());
  if (mean <= 0) return 0.0;
  for (int c : counts) var += (c - mean) * (c - mean);
  var /= static_cast<double>(counts.size());
  return std::sqrt(var) / mean;
}

}  // namespace plslam::features
