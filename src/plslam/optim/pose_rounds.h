#pragma once
// The rounds of a single-frame optimisation, shared by the pose-only one (pose_only.cpp) and the
// inertial one (inertial/inertial_pose.cpp), whatever the state (a pose, or pose, velocity and
// biases): `rounds` rounds of Levenberg-Marquardt, the Huber kernels in the first `robust_rounds`,
// and after each round every visual term re-classified by its chi-square gate, so that outliers
// can come back once the pose has improved. A round with the same active set and kernel as the one
// before is skipped: it would start at its own optimum and end with the same classification.
#include <algorithm>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "plslam/optim/pose_only.h"
#include "plslam/optim/pose_terms.h"

namespace plslam::optim {

// `evaluate(x, robust, H, g)` returns the cost at x (under the kernels when robust) of the visual
// terms not flagged out in `res` plus whatever else the state carries, and fills the normal
// equations H (N x N) and g of its tangent; `plus(x, delta)` moves x by a tangent step;
// `camera_pose(x)` is the T_cw the visual terms are classified at. Fills `res`'s flags, inlier
// counts, final visual cost and iterations (not its pose); returns the final state.
template <int N, class State, class Evaluate, class Plus, class CameraPose>
State run_pose_rounds(const PoseTerms& terms, const PoseOnlyOptions& options, State x, PoseOnlyResult& res,
                      const Evaluate& evaluate, const Plus& plus, const CameraPose& camera_pose) {
  using MatrixN = Eigen::Matrix<double, N, N>;
  using VectorN = Eigen::Matrix<double, N, 1>;
  res.point_outlier.assign(terms.num_points(), false);
  res.line_outlier.assign(terms.num_lines(), false);
  bool changed = true;  // did the last classification change any flag?
  for (int round = 0; round < options.rounds; ++round) {
    const bool robust = round < options.robust_rounds;
    if (round > 0 && !changed && robust == (round - 1 < options.robust_rounds)) continue;
    double lambda = 1e-5;
    MatrixN H;
    VectorN g;
    double cost = evaluate(x, robust, &H, &g);
    for (int it = 0; it < options.iterations_per_round; ++it) {
      ++res.iterations;
      // Marquardt's scaled damping; the tiny absolute term keeps A invertible when a direction is
      // unobserved (e.g. a single line).
      MatrixN A = H;
      A.diagonal() += lambda * H.diagonal() + VectorN::Constant(1e-12 * H.diagonal().maxCoeff());
      const VectorN delta = A.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      const State x_new = plus(x, delta);
      // The normal equations at x_new come with its cost in the same pass: steps are rarely
      // rejected, so this saves a full cost-only pass per iteration.
      MatrixN H_new;
      VectorN g_new;
      const double new_cost = evaluate(x_new, robust, &H_new, &g_new);
      if (new_cost < cost) {
        x = x_new;
        lambda = std::max(lambda / 3.0, 1e-9);
        const double old_cost = cost;
        cost = new_cost;
        H = H_new;
        g = g_new;
        // Converged: a sub-micrometre / sub-microradian step or a negligible cost decrease.
        if (delta.squaredNorm() < 1e-12 || old_cost - new_cost < 1e-9 * old_cost) break;
      } else {
        // A sub-micrometre / sub-microradian step that does not lower the cost: at the optimum,
        // where the cost change is rounding noise, more damping would only repeat it.
        if (delta.squaredNorm() < 1e-12) break;
        lambda *= 4.0;
        if (lambda > 1e8) break;
      }
    }
    const std::vector<bool> prev_points = res.point_outlier, prev_lines = res.line_outlier;
    res.final_cost = terms.classify(camera_pose(x), &res.point_outlier, &res.line_outlier);
    changed = prev_points != res.point_outlier || prev_lines != res.line_outlier;
  }
  res.num_point_inliers = static_cast<int>(std::count(res.point_outlier.begin(), res.point_outlier.end(), false));
  res.num_line_inliers = static_cast<int>(std::count(res.line_outlier.begin(), res.line_outlier.end(), false));
  return x;
}

}  // namespace plslam::optim
