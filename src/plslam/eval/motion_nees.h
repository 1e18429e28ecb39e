#pragma once
// Is a pose covariance consistent? The normalised estimation error squared (NEES) of each
// frame-to-frame motion against the ground truth: e' S^-1 e, with e the motion's error and S its
// covariance from the two poses'. For a consistent estimator with Gaussian errors its mean is the
// degrees of freedom, 6; over it, the covariance is too small (overconfident), under it too large.
#include <cstddef>
#include <vector>

#include "plslam/core/types.h"
#include "plslam/geometry/se3.h"

namespace plslam::eval {

// A pose with its covariance: of xi in T_true = T exp(xi), xi = (translation, rotation) in the
// pose's own (camera) frame, as tracking::TrackResult::pose_covariance gives it.
struct CovariantPose {
  double t = 0;
  geometry::SE3 T_wc;
  geometry::Matrix6d covariance = geometry::Matrix6d::Zero();
};

struct MotionNees {
  std::vector<double> nees;  // per motion scored, in order
  double mean = 0;           // of nees; 0 when none
  double median = 0;         // numpy's: the two middle values averaged (eval::compute_statistics)
  std::size_t dof = 6;
};

// The covariance of the motion T_12 = T_1^-1 T_2 in its own right perturbation, the two poses'
// errors taken as independent: Ad(T_12^-1) S_1 Ad(T_12^-1)' + S_2.
geometry::Matrix6d motion_covariance(const geometry::SE3& T_12, const geometry::Matrix6d& S1,
                                     const geometry::Matrix6d& S2);

// NEES of error xi (T_true = T_est exp(xi)) under covariance S: xi' S^-1 xi; negative when S is not
// positive definite.
double nees(const geometry::Vector6d& xi, const geometry::Matrix6d& S);

// Every pair of consecutive estimated poses (in time order) at most `max_gap_s` apart, both with a
// covariance and both with a ground-truth pose within `max_diff_s` of their time, is scored.
// Ground truth in any world frame (motions do not depend on it), camera poses T_wc.
MotionNees motion_nees(const Trajectory& ground_truth, const std::vector<CovariantPose>& estimate, double max_gap_s,
                       double max_diff_s = 0.01);

}  // namespace plslam::eval
