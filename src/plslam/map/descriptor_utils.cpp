#include "plslam/map/descriptor_utils.h"

#include "plslam/features/orb_descriptor.h"

#include <algorithm>
#include <limits>

namespace plslam::map {

int descriptor_distance(const cv::Mat& a, const cv::Mat& b) {
  return features::hamming_distance(a.ptr<uint8_t>(0), b.ptr<uint8_t>(0));
}

cv::Mat most_distinctive(const std::vector<cv::Mat>& descriptors) {
  const std::size_t n = descriptors.size();
  if (n == 0) return {};
  std::vector<std::vector<int>> d(n, std::vector<int>(n, 0));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) d[i][j] = d[j][i] = descriptor_distance(descriptors[i], descriptors[j]);
  }
  int best = std::numeric_limits<int>::max();
  std::size_t best_i = 0;
  for (std::size_t i = 0; i < n; ++i) {
    auto row = d[i];
    std::nth_element(row.begin(), row.begin() + static_cast<std::ptrdiff_t>((n - 1) / 2), row.end());
    const int median = row[(n - 1) / 2];
    if (median < best) {
      best = median;
      best_i = i;
    }
  }
  return descriptors[best_i].clone();
}

}  // namespace plslam::map
