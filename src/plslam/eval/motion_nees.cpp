#include "plslam/eval/motion_nees.h"

#include <Eigen/Cholesky>

#include "plslam/eval/association.h"
#include "plslam/eval/statistics.h"

namespace plslam::eval {

using geometry::Matrix6d;
using geometry::SE3;

Matrix6d motion_covariance(const SE3& T_12, const Matrix6d& S1, const Matrix6d& S2) {
  // (T_1 exp(xi1))^-1 T_2 exp(xi2) = exp(-xi1) T_12 exp(xi2) = T_12 exp(-Ad(T_12^-1) xi1) exp(xi2): to
  // first order the motion's error is xi2 - Ad(T_12^-1) xi1.
  const Matrix6d A = T_12.inverse().adjoint();
  return A * S1 * A.transpose() + S2;
}

double nees(const geometry::Vector6d& xi, const Matrix6d& S) {
  const Eigen::LLT<Matrix6d> llt(S);
  if (llt.info() != Eigen::Success) return -1;
  return xi.dot(llt.solve(xi));
}

MotionNees motion_nees(const Trajectory& ground_truth, const std::vector<CovariantPose>& estimate, double max_gap_s,
                       double max_diff_s) {
  std::vector<double> gt_times, est_times;
  for (const auto& p : ground_truth) gt_times.push_back(p.t);
  for (const auto& p : estimate) est_times.push_back(p.t);
  const auto pairs = associate_by_time(gt_times, est_times, max_diff_s);
  // The ground-truth pose of each estimated pose, where it has one.
  std::vector<const StampedPose*> gt_of(estimate.size(), nullptr);
  for (std::size_t k = 0; k < pairs.size(); ++k) gt_of[pairs.est[k]] = &ground_truth[pairs.gt[k]];
  MotionNees out;
  for (std::size_t i = 0; i + 1 < estimate.size(); ++i) {
    const auto &a = estimate[i], &b = estimate[i + 1];
    if (!gt_of[i] || !gt_of[i + 1] || b.t - a.t > max_gap_s) continue;
    if (a.covariance.isZero(0) || b.covariance.isZero(0)) continue;
    const SE3 est_12 = a.T_wc.inverse() * b.T_wc;
    const SE3 gt_12 = SE3(gt_of[i]->T).inverse() * SE3(gt_of[i + 1]->T);
    const double e = nees((est_12.inverse() * gt_12).log(), motion_covariance(est_12, a.covariance, b.covariance));
    if (e >= 0) out.nees.push_back(e);
  }
  if (!out.nees.empty()) {
    const auto stats = compute_statistics(out.nees);
    out.mean = stats.mean;
    out.median = stats.median;
  }
  return out;
}

}  // namespace plslam::eval
