#include "plslam/optim/pose_terms.h"

#include <Eigen/Cholesky>

#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

PoseTerms::PoseTerms(const geometry::StereoCamera& cam, const std::vector<PosePointTerm>& points,
                     const std::vector<PoseLineTerm>& lines, const PoseOnlyOptions& options)
    : cam_(cam), points_(points), lines_(lines), options_(options) {
  point_info_.reserve(points.size());
  for (const auto& t : points) point_info_.push_back(level_information(t.obs.level, options.scale_factor));
  line_info_.reserve(lines.size());
  for (const auto& t : lines) line_info_.push_back(t.obs.information * level_information(t.obs.level, options.scale_factor));
}

double PoseTerms::evaluate(const SE3& T, const std::vector<bool>& point_out, const std::vector<bool>& line_out,
                           bool robust, Matrix6d* H, Vector6d* g) const {
  double cost = 0.0;
  const bool jac = H != nullptr;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (point_out[i]) continue;
    const auto& t = points_[i];
    const Eigen::Vector3d Xc = T * t.world;
    if (!(Xc.z() > 0.0)) continue;  // behind the camera: contributes nothing this iteration
    const Eigen::Vector3d r = stereo_point_residual_at(cam_, Xc, t.obs.measurement, t.obs.has_right);
    const double info = point_info_[i];
    const double s = info * r.squaredNorm();
    const Huber h{t.obs.has_right ? options_.chi2_point_stereo : options_.chi2_point_mono};
    cost += robust ? h.rho(s) : s;
    if (jac) {
      // w J'J and w J'r from the projection Jacobian's structure (stereo_point_residual.h).
      const double w = info * (robust ? h.weight(s) : 1.0);
      Eigen::Matrix3d B;
      Eigen::Vector3d a;
      stereo_point_weighted_normal(cam_, Xc, r, t.obs.has_right, w, &B, &a);
      add_pose_normal_equations(B, a, Xc, *H, *g);
    }
  }
  const Huber hl{options_.chi2_line_pair};
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    if (line_out[i]) continue;
    const auto& t = lines_[i];
    const Eigen::Vector3d Xs = T * t.start, Xe = T * t.end;
    if (!(Xs.z() > 0.0) || !(Xe.z() > 0.0)) continue;
    const Eigen::Vector4d rl = stereo_line_residual_at(cam_, Xs, Xe, t.obs);
    const double info = line_info_[i];
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
      stereo_line_weighted_normal(cam_, Xs, Xe, t.obs, rl, w, B, a);
      add_pose_normal_equations(B[0], a[0], Xs, *H, *g);
      add_pose_normal_equations(B[1], a[1], Xe, *H, *g);
    }
  }
  return cost;
}

double PoseTerms::classify(const SE3& T, std::vector<bool>* point_out, std::vector<bool>* line_out) const {
  double cost = 0.0;
  Eigen::Vector3d r;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const auto& t = points_[i];
    const double th = t.obs.has_right ? options_.chi2_point_stereo : options_.chi2_point_mono;
    bool out = true;
    if (evaluate_stereo_point(cam_, T, t.world, t.obs.measurement, t.obs.has_right, &r, nullptr,
                              nullptr)) {
      const double s = point_info_[i] * r.squaredNorm();
      out = s > th;
      if (!out) cost += s;
    }
    (*point_out)[i] = out;
  }
  Eigen::Vector4d rl;
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    const auto& t = lines_[i];
    bool out = true;
    if (evaluate_stereo_line(cam_, T, t.start, t.end, t.obs, &rl, nullptr, nullptr, nullptr)) {
      const double sl = line_info_[i] * rl.head<2>().squaredNorm();
      const double sr = line_info_[i] * rl.tail<2>().squaredNorm();
      out = sl > options_.chi2_line_pair || sr > options_.chi2_line_pair;
      if (!out) cost += sl + sr;
    }
    (*line_out)[i] = out;
  }
  return cost;
}

geometry::Matrix6d PoseTerms::covariance(const geometry::SE3& T_cw, const std::vector<bool>& point_out,
                                         const std::vector<bool>& line_out) const {
  geometry::Matrix6d H = geometry::Matrix6d::Zero();
  geometry::Vector6d g = geometry::Vector6d::Zero();
  evaluate(T_cw, point_out, line_out, /*robust=*/false, &H, &g);
  const Eigen::LDLT<geometry::Matrix6d> ldlt(H);
  // A direction no inlier observes (a rank-deficient H) has no finite covariance.
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
      !(ldlt.vectorD().array() > 1e-9 * H.diagonal().maxCoeff()).all()) {
    return geometry::Matrix6d::Zero();
  }
  const geometry::Matrix6d C = ldlt.solve(geometry::Matrix6d::Identity());
  return 0.5 * (C + C.transpose());
}

}  // namespace plslam::optim
