#include "plslam/optim/pose_only.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "plslam/optim/lm_damping.h"
#include "plslam/optim/pose_terms.h"

namespace plslam::optim {
namespace {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

}  // namespace

PoseOnlyResult optimize_pose(const geometry::StereoCamera& cam, const SE3& T_cw_init,
                             const std::vector<PosePointTerm>& points,
                             const std::vector<PoseLineTerm>& lines,
                             const PoseOnlyOptions& options) {
  const PoseTerms p(cam, points, lines, options);

  PoseOnlyResult res;
  res.T_cw = T_cw_init;
  res.point_outlier.assign(points.size(), false);
  res.line_outlier.assign(lines.size(), false);
  SE3 T = T_cw_init;

  bool changed = true;  // did the last classification change any flag?
  for (int round = 0; round < options.rounds; ++round) {
    const bool robust = round < options.robust_rounds;
    // Same active set and same kernel as the round just finished: it would start at its own
    // converged optimum and end with the same classification, so skip it.
    if (round > 0 && !changed && robust == (round - 1 < options.robust_rounds)) continue;
    LmDamping damping;
    Matrix6d H;
    Vector6d g;
    H.setZero();
    g.setZero();
    double cost = p.evaluate(T, res.point_outlier, res.line_outlier, robust, &H, &g);
    for (int it = 0; it < options.iterations_per_round; ++it) {
      ++res.iterations;
      const Matrix6d& Hs = H;
      const double lambda = damping.lambda;
      // Marquardt's scaled damping; the tiny absolute term keeps A invertible when a
      // direction is unobserved (e.g. a single line).
      Matrix6d A = Hs;
      A.diagonal() += lambda * Hs.diagonal() + Vector6d::Constant(1e-12 * Hs.diagonal().maxCoeff());
      const Vector6d delta = A.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      const SE3 T_new = SE3::exp(delta) * T;
      // The normal equations at T_new come with its cost in the same pass: steps are rarely
      // rejected, so this saves a full cost-only pass per iteration.
      Matrix6d H_new = Matrix6d::Zero();
      Vector6d g_new = Vector6d::Zero();
      const double new_cost =
          p.evaluate(T_new, res.point_outlier, res.line_outlier, robust, &H_new, &g_new);
      if (new_cost < cost) {
        T = T_new;
        const double old_cost = cost;
        cost = new_cost;
        H = H_new;
        g = g_new;
        if (damping.accepted(delta.squaredNorm(), old_cost, new_cost)) break;
      } else if (damping.rejected(delta.squaredNorm())) {
        break;
      }
    }
    const std::vector<bool> prev_points = res.point_outlier, prev_lines = res.line_outlier;
    res.final_cost = p.classify(T, &res.point_outlier, &res.line_outlier);
    changed = prev_points != res.point_outlier || prev_lines != res.line_outlier;
  }
  res.T_cw = T;
  if (options.covariance) {
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    p.evaluate(T, res.point_outlier, res.line_outlier, /*robust=*/false, &H, &g);
    const Eigen::LDLT<Matrix6d> ldlt(H);
    // A direction no inlier observes (a rank-deficient H) has no finite covariance.
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() && (ldlt.vectorD().array() > 1e-9 * H.diagonal().maxCoeff()).all()) {
      res.covariance = ldlt.solve(Matrix6d::Identity());
      res.covariance = 0.5 * (res.covariance + res.covariance.transpose()).eval();
    }
  }
  for (const bool o : res.point_outlier) res.num_point_inliers += o ? 0 : 1;
  for (const bool o : res.line_outlier) res.num_line_inliers += o ? 0 : 1;
  return res;
}

}  // namespace plslam::optim
