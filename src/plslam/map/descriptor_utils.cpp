#include "plslam/map/descriptor_utils.h"

#include "plslam/features/orb_descriptor.h"

#include <algorithm>
#include <limits>

namespace plslam::map {

int descriptor_distance(const cv::Mat& a, const cv::Mat& b) {
  return features::hamming_distance(a.ptr<uint8_t>(0), b.ptr<uint8_t>(0));
}

std::size_t most_distinctive_index(const std::vector<const uint8_t*>& rows) {
  const std::size_t n = rows.size();
  if (n < 3) return 0;  // with one or two rows, the first has the smallest median (ties: the first)
  // One flat matrix and one scratch row: this runs for every landmark a keyframe touches, and
  // the allocations of a matrix of rows were as costly as the distances.
  std::vector<int> d(n * n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) d[i * n + j] = d[j * n + i] = features::hamming_distance(rows[i], rows[j]);
  }
  const auto mid = static_cast<std::ptrdiff_t>((n - 1) / 2);
  std::vector<int> row(n);
  int best = std::numeric_limits<int>::max();
  std::size_t best_i = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(d.begin() + static_cast<std::ptrdiff_t>(i * n), d.begin() + static_cast<std::ptrdiff_t>((i + 1) * n),
              row.begin());
    std::nth_element(row.begin(), row.begin() + mid, row.end());
    if (row[static_cast<std::size_t>(mid)] < best) {
      best = row[static_cast<std::size_t>(mid)];
      best_i = i;
    }
  }
  return best_i;
}

}  // namespace plslam::map
