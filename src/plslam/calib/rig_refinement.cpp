#include "plslam/calib/rig_refinement.h"

#include <cmath>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

namespace plslam::calib {

template <class T>
bool project_lens(geometry::LensModel model, const T* k, const T* X, T* uv) {
  using std::atan2;
  using std::sqrt;
  T xd, yd;
  if (model == geometry::LensModel::kRadialTangential) {
    if (!(X[2] > T(1e-9))) return false;
    const T x = X[0] / X[2], y = X[1] / X[2];
    const T r2 = x * x + y * y;
    const T radial = T(1) + k[4] * r2 + k[5] * r2 * r2;
    xd = x * radial + T(2) * k[6] * x * y + k[7] * (r2 + T(2) * x * x);
    yd = y * radial + k[6] * (r2 + T(2) * y * y) + T(2) * k[7] * x * y;
  } else {
    const T rho2 = X[0] * X[0] + X[1] * X[1];
    if (rho2 < T(1e-18)) {  // on the axis: the limit of theta_d / rho is 1 / Z
      if (!(X[2] > T(0))) return false;
      xd = X[0] / X[2];
      yd = X[1] / X[2];
    } else {
      const T rho = sqrt(rho2);
      const T theta = atan2(rho, X[2]);
      const T t2 = theta * theta;
      const T theta_d = theta * (T(1) + t2 * (k[4] + t2 * (k[5] + t2 * (k[6] + t2 * k[7]))));
      xd = X[0] * theta_d / rho;
      yd = X[1] * theta_d / rho;
    }
  }
  uv[0] = k[0] * xd + k[2];
  uv[1] = k[1] * yd + k[3];
  return true;
}

template bool project_lens<double>(geometry::LensModel, const double*, const double*, double*);

namespace {

// A board corner seen by the left camera (pose: the board in the left camera's frame) or, through
// the rig, by the right one.
struct CornerResidual {
  geometry::LensModel model;
  Eigen::Vector3d X;  // board frame
  Eigen::Vector2d observed;

  template <class T>
  bool operator()(const T* intrinsics, const T* board_pose, T* residual) const {
    T Xb[3] = {T(X.x()), T(X.y()), T(X.z())}, Xc[3], uv[2];
    ceres::AngleAxisRotatePoint(board_pose, Xb, Xc);
    for (int i = 0; i < 3; ++i) Xc[i] += board_pose[3 + i];
    if (!project_lens(model, intrinsics, Xc, uv)) return false;
    residual[0] = uv[0] - T(observed.x());
    residual[1] = uv[1] - T(observed.y());
    return true;
  }
};

struct RightCornerResidual {
  CornerResidual left_frame;

  template <class T>
  bool operator()(const T* intrinsics, const T* right_left, const T* board_pose, T* residual) const {
    // The board in the right camera's frame: compose the rig with the board pose.
    T Xb[3] = {T(left_frame.X.x()), T(left_frame.X.y()), T(left_frame.X.z())}, Xl[3], Xr[3], uv[2];
    ceres::AngleAxisRotatePoint(board_pose, Xb, Xl);
    for (int i = 0; i < 3; ++i) Xl[i] += board_pose[3 + i];
    ceres::AngleAxisRotatePoint(right_left, Xl, Xr);
    for (int i = 0; i < 3; ++i) Xr[i] += right_left[3 + i];
    if (!project_lens(left_frame.model, intrinsics, Xr, uv)) return false;
    residual[0] = uv[0] - T(left_frame.observed.x());
    residual[1] = uv[1] - T(left_frame.observed.y());
    return true;
  }
};

std::array<double, 8> intrinsics_of(const geometry::LensCamera& c) {
  return {c.fx, c.fy, c.cx, c.cy, c.coeffs[0], c.coeffs[1], c.coeffs[2], c.coeffs[3]};
}

geometry::LensCamera lens_from(const geometry::LensCamera& like, const std::array<double, 8>& k) {
  geometry::LensCamera c = like;
  c.fx = k[0];
  c.fy = k[1];
  c.cx = k[2];
  c.cy = k[3];
  for (int i = 0; i < 4; ++i) c.coeffs[static_cast<std::size_t>(i)] = k[static_cast<std::size_t>(4 + i)];
  return c;
}

std::array<double, 6> pose_params(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.rotation());
  const Eigen::Vector3d r = aa.axis() * aa.angle();
  return {r.x(), r.y(), r.z(), T.translation().x(), T.translation().y(), T.translation().z()};
}

Eigen::Isometry3d pose_from(const std::array<double, 6>& p) {
  const Eigen::Vector3d r(p[0], p[1], p[2]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (r.norm() > 0) T.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(p[3], p[4], p[5]);
  return T;
}

}  // namespace

RigRefinement refine_rig(const geometry::LensCamera& left, const geometry::LensCamera& right,
                         const Eigen::Isometry3d& T_right_left, const std::vector<RigView>& views,
                         const std::vector<cv::Point3f>& corners, bool hold_distortion) {
  std::array<double, 8> kl = intrinsics_of(left), kr = intrinsics_of(right);
  std::array<double, 6> rig = pose_params(T_right_left);
  std::vector<std::array<double, 6>> poses;
  for (const auto& v : views) poses.push_back(pose_params(v.T_left_board));
  ceres::Problem problem;
  // Huber at 1 px: a mislocated corner (a marker's edge pulled it) must not bend the lens.
  auto robust = [] { return new ceres::HuberLoss(1.0); };
  int observations = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (const auto& o : views[i].left) {
      const auto& P = corners.at(static_cast<std::size_t>(o.corner));
      auto* cost = new ceres::AutoDiffCostFunction<CornerResidual, 2, 8, 6>(
          new CornerResidual{left.model, Eigen::Vector3d(P.x, P.y, P.z), Eigen::Vector2d(o.pixel.x, o.pixel.y)});
      problem.AddResidualBlock(cost, robust(), kl.data(), poses[i].data());
      ++observations;
    }
    for (const auto& o : views[i].right) {
      const auto& P = corners.at(static_cast<std::size_t>(o.corner));
      auto* cost = new ceres::AutoDiffCostFunction<RightCornerResidual, 2, 8, 6, 6>(new RightCornerResidual{
          {right.model, Eigen::Vector3d(P.x, P.y, P.z), Eigen::Vector2d(o.pixel.x, o.pixel.y)}});
      problem.AddResidualBlock(cost, robust(), kr.data(), rig.data(), poses[i].data());
      ++observations;
    }
  }
  RigRefinement out;
  out.observations = observations;
  if (hold_distortion) {
    for (double* k : {kl.data(), kr.data()}) {
      if (problem.HasParameterBlock(k)) problem.SetManifold(k, new ceres::SubsetManifold(8, {4, 5, 6, 7}));
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 100;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.left = lens_from(left, kl);
  out.right = lens_from(right, kr);
  out.T_right_left = pose_from(rig);
  // RMS of the plain (not robustified) errors.
  double sum = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (const auto& [obs, k, extra, errors] : {std::tuple{&views[i].left, &kl, false, &out.left_errors},
                                                std::tuple{&views[i].right, &kr, true, &out.right_errors}}) {
      for (const auto& o : *obs) {
        const auto& P = corners.at(static_cast<std::size_t>(o.corner));
        Eigen::Vector3d X = pose_from(poses[i]) * Eigen::Vector3d(P.x, P.y, P.z);
        if (extra) X = out.T_right_left * X;
        double uv[2];
        if (!project_lens(left.model, k->data(), X.data(), uv)) continue;
        sum += (uv[0] - o.pixel.x) * (uv[0] - o.pixel.x) + (uv[1] - o.pixel.y) * (uv[1] - o.pixel.y);
        errors->push_back({static_cast<int>(i), o.pixel,
                           cv::Point2f(static_cast<float>(uv[0] - o.pixel.x), static_cast<float>(uv[1] - o.pixel.y))});
      }
    }
  }
  out.rms_px = observations > 0 ? std::sqrt(sum / observations) : 0.0;
  return out;
}

}  // namespace plslam::calib
