#include "plslam/eval/association.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::eval {
namespace {

// Index of the stamp in `sorted` nearest to t; the lower index wins a tie, as numpy's argmin.
// |s - t| is unimodal over sorted s (rounding of s - t is monotone), so the nearest stamp is one
// of the two around the insertion point.
std::size_t nearest(const std::vector<double>& sorted, double t) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), t);
  std::size_t j = static_cast<std::size_t>(it - sorted.begin());
  if (j == sorted.size() || (j > 0 && std::abs(sorted[j - 1] - t) <= std::abs(sorted[j] - t))) {
    // The first of repeated stamps, as argmin would pick.
    j = static_cast<std::size_t>(std::lower_bound(sorted.begin(), sorted.end(), sorted[j - 1]) -
                                 sorted.begin());
  }
  return j;
}

}  // namespace

IndexPairs associate_by_time(const std::vector<double>& gt_times,
                             const std::vector<double>& est_times, double max_diff) {
  IndexPairs pairs;
  if (gt_times.empty() || est_times.empty()) return pairs;
  const bool est_longer = est_times.size() > gt_times.size();
  const auto& shorter = est_longer ? gt_times : est_times;
  const auto& longer = est_longer ? est_times : gt_times;
  std::vector<std::size_t> idx_short;
  std::vector<std::size_t> idx_long;
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    const std::size_t j = nearest(longer, shorter[i]);
    if (std::abs(longer[j] - shorter[i]) <= max_diff) {
      idx_short.push_back(i);
      idx_long.push_back(j);
    }
  }
  pairs.gt = est_longer ? std::move(idx_short) : std::move(idx_long);
  pairs.est = est_longer ? std::move(idx_long) : std::move(idx_short);
  return pairs;
}

IndexPairs associate_by_index(std::size_t gt_size, std::size_t est_size) {
  if (gt_size != est_size) {
    throw InputError("", fmt::format("poses are paired by index (KITTI format has no timestamps) "
                                     "but the ground truth has {} poses and the estimate {}",
                                     gt_size, est_size));
  }
  IndexPairs pairs;
  pairs.gt.resize(gt_size);
  for (std::size_t i = 0; i < gt_size; ++i) pairs.gt[i] = i;
  pairs.est = pairs.gt;
  return pairs;
}

}  // namespace plslam::eval
