#include "plslam/optim/pose_only.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {
namespace {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

struct Problem {
  const geometry::StereoCamera& cam;
  const std::vector<PosePointTerm>& points;
  const std::vector<PoseLineTerm>& lines;
  const PoseOnlyOptions& opt;
  std::vector<double> point_info;  // per term, precomputed
  std::vector<double> line_info;
};

// Robust cost of the active terms at T; optionally accumulates the IRLS normal equations.
double evaluate(const Problem& p, const SE3& T, const std::vector<bool>& point_out,
                const std::vector<bool>& line_out, bool robust, Matrix6d* H, Vector6d* g) {
  double cost = 0.0;
  const bool jac = H != nullptr;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (point_out[i]) continue;
    const auto& t = p.points[i];
    const Eigen::Vector3d Xc = T * t.world;
    if (!(Xc.z() > 0.0)) continue;  // behind the camera: contributes nothing this iteration
    const Eigen::Vector3d r = stereo_point_residual_at(p.cam, Xc, t.obs.measurement, t.obs.has_right);
    const double info = p.point_info[i];
    const double s = info * r.squaredNorm();
    const Huber h{t.obs.has_right ? p.opt.chi2_point_stereo : p.opt.chi2_point_mono};
    cost += robust ? h.rho(s) : s;
    if (jac) {
      // w J'J and w J'r from the projection Jacobian's structure (stereo_point_residual.h).
      const double w = info * (robust ? h.weight(s) : 1.0);
      Eigen::Matrix3d B;
      Eigen::Vector3d a;
      stereo_point_weighted_normal(p.cam, Xc, r, t.obs.has_right, w, &B, &a);
      add_pose_normal_equations(B, a, Xc, *H, *g);
    }
  }
  const Huber hl{p.opt.chi2_line_pair};
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    if (line_out[i]) continue;
    const auto& t = p.lines[i];
    const Eigen::Vector3d Xs = T * t.start, Xe = T * t.end;
    if (!(Xs.z() > 0.0) || !(Xe.z() > 0.0)) continue;
    const Eigen::Vector4d rl = stereo_line_residual_at(p.cam, Xs, Xe, t.obs);
    const double info = p.line_info[i];
    // Two independent Huber pairs: left image rows 0-1, right image rows 2-3.
    Eigen::Vector2d w;
    for (int pair = 0; pair < 2; ++pair) {
      const double s = info * rl.segment<2>(2 * pair).squaredNorm();
      cost += robust ? hl.rho(s) : s;
      w(pair) = info * (robust ? hl.weight(s) : 1.0);
    }
    if (jac) {
      // Each endpoint as a weighted 2-row point observation (stereo_line_residual.h).
      Eigen::Matrix3d B[2];
      Eigen::Vector3d a[2];
      stereo_line_weighted_normal(p.cam, Xs, Xe, t.obs, rl, w, B, a);
      add_pose_normal_equations(B[0], a[0], Xs, *H, *g);
      add_pose_normal_equations(B[1], a[1], Xe, *H, *g);
    }
  }
  return cost;
}

// Marks outliers by the chi-square gates at T; returns the robust-free cost of the inliers.
double classify(const Problem& p, const SE3& T, std::vector<bool>* point_out,
                std::vector<bool>* line_out) {
  double cost = 0.0;
  Eigen::Vector3d r;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const auto& t = p.points[i];
    const double th = t.obs.has_right ? p.opt.chi2_point_stereo : p.opt.chi2_point_mono;
    bool out = true;
    if (evaluate_stereo_point(p.cam, T, t.world, t.obs.measurement, t.obs.has_right, &r, nullptr,
                              nullptr)) {
      const double s = p.point_info[i] * r.squaredNorm();
      out = s > th;
      if (!out) cost += s;
    }
    (*point_out)[i] = out;
  }
  Eigen::Vector4d rl;
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    const auto& t = p.lines[i];
    bool out = true;
    if (evaluate_stereo_line(p.cam, T, t.start, t.end, t.obs, &rl, nullptr, nullptr, nullptr)) {
      const double sl = p.line_info[i] * rl.head<2>().squaredNorm();
      const double sr = p.line_info[i] * rl.tail<2>().squaredNorm();
      out = sl > p.opt.chi2_line_pair || sr > p.opt.chi2_line_pair;
      if (!out) cost += sl + sr;
    }
    (*line_out)[i] = out;
  }
  return cost;
}

}  // namespace

PoseOnlyResult optimize_pose(const geometry::StereoCamera& cam, const SE3& T_cw_init,
                             const std::vector<PosePointTerm>& points,
                             const std::vector<PoseLineTerm>& lines,
                             const PoseOnlyOptions& options) {
  Problem p{cam, points, lines, options, {}, {}};
  p.point_info.reserve(points.size());
  for (const auto& t : points) p.point_info.push_back(level_information(t.obs.level, options.scale_factor));
  p.line_info.reserve(lines.size());
  for (const auto& t : lines) {
    p.line_info.push_back(t.obs.information * level_information(t.obs.level, options.scale_factor));
  }

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
    double lambda = -1.0;
    Matrix6d H;
    Vector6d g;
    H.setZero();
    g.setZero();
    double cost = evaluate(p, T, res.point_outlier, res.line_outlier, robust, &H, &g);
    for (int it = 0; it < options.iterations_per_round; ++it) {
      ++res.iterations;
      const Matrix6d& Hs = H;
      if (lambda < 0.0) lambda = 1e-5;
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
          evaluate(p, T_new, res.point_outlier, res.line_outlier, robust, &H_new, &g_new);
      if (new_cost < cost) {
        T = T_new;
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
    res.final_cost = classify(p, T, &res.point_outlier, &res.line_outlier);
    changed = prev_points != res.point_outlier || prev_lines != res.line_outlier;
  }
  res.T_cw = T;
  if (options.covariance) {
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    evaluate(p, T, res.point_outlier, res.line_outlier, /*robust=*/false, &H, &g);
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
