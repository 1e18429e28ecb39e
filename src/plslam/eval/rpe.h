#pragma once
// Relative pose error with evo's definitions: for an index pair (i, j),
//   E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j)   with Q the ground truth and P the estimate,
// the translation error is ||t(E)|| and the rotation error the angle of R(E). The pairs are
// chosen on the estimate's poses (evo's default, pairs_from_reference = false).
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "plslam/core/types.h"

namespace plslam::eval {

enum class DeltaUnit { kFrames, kMeters };

struct RpeOptions {
  double delta = 1.0;                       // frames (a positive integer) or metres of path
  DeltaUnit unit = DeltaUnit::kFrames;
  bool all_pairs = false;                   // every start pose instead of consecutive pairs
  double rel_delta_tol = 0.1;               // all-pairs in metres: accept |path - delta| <= tol*delta
};

using IdPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// evo's id_pairs_from_delta:
//  frames, consecutive: (0,d), (d,2d), ...;  frames, all pairs: (i, i+d) for every i.
//  metres, consecutive: the path length is accumulated from pose 0 and reset each time it
//    reaches delta; the poses where it did are the ids, paired consecutively.
//  metres, all pairs: for each i, the first j > i whose path length from i is nearest to delta,
//    kept when within rel_delta_tol * delta.
// Throws InputError when delta is invalid or yields no pair.
IdPairs rpe_id_pairs(const Trajectory& poses, const RpeOptions& options);

struct RpeErrors {
  IdPairs pairs;
  std::vector<double> trans_m;
  std::vector<double> rot_deg;
};

// gt and est paired pose by pose (same length).
RpeErrors compute_rpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options);

// Rotation angle in radians, in [0, pi], accurate also for tiny angles (unlike acos of the trace).
double rotation_angle(const Eigen::Matrix3d& R);

}  // namespace plslam::eval
