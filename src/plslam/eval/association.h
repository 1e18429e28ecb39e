#pragma once
// Pairing of ground-truth and estimated poses before any error is computed.
#include <cstddef>
#include <vector>

namespace plslam::eval {

// Matched indices: gt[k] pairs with est[k].
struct IndexPairs {
  std::vector<std::size_t> gt;
  std::vector<std::size_t> est;
  std::size_t size() const { return gt.size(); }
};

// evo's associate_trajectories: each stamp of the shorter list (the estimate when both are equally
// long) is matched to the nearest stamp of the longer one, the first on a tie, and kept when
// |dt| <= max_diff. A stamp of the longer list may thus be used twice. Both lists must be sorted
// (repeated stamps allowed).
IndexPairs associate_by_time(const std::vector<double>& gt_times,
                             const std::vector<double>& est_times, double max_diff);

// Pose i with pose i, for files without timestamps (KITTI). Throws InputError when the lengths
// differ, naming both.
IndexPairs associate_by_index(std::size_t gt_size, std::size_t est_size);

}  // namespace plslam::eval
