#include "plslam/inertial/inertial_pose.h"

#include <stdexcept>

#include "plslam/inertial/imu_pose_manifold.h"
#include "plslam/optim/pose_rounds.h"
#include "plslam/optim/pose_terms.h"

namespace plslam::inertial {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

InertialState predict(const InertialState& i, const Preintegration& i_to_j) {
  const double dt = i_to_j.dt();
  const Eigen::Vector3d g = world_gravity();
  const Eigen::Matrix3d& R_i = i.T_wb.rotation();
  const Eigen::Vector3d& p_i = i.T_wb.translation();
  InertialState j;
  j.T_wb = SE3(Eigen::Quaterniond(R_i * i_to_j.corrected_delta_R(i.bias)).normalized(),
               p_i + i.v * dt + 0.5 * dt * dt * g + R_i * i_to_j.corrected_delta_p(i.bias));
  j.v = i.v + g * dt + R_i * i_to_j.corrected_delta_v(i.bias);
  j.bias = i.bias;
  return j;
}

std::vector<Eigen::Vector3d> seed_velocities(std::span<const SE3> T_wb, std::span<const Preintegration* const> from_previous,
                                             const ImuBias& bias) {
  if (from_previous.size() != T_wb.size()) throw std::invalid_argument("seed_velocities: one interval per pose");
  std::vector<Eigen::Vector3d> v(T_wb.size(), Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < T_wb.size(); ++k) {
    if (const Preintegration* next = k + 1 < T_wb.size() ? from_previous[k + 1] : nullptr) {
      const Eigen::Vector3d at_rest = predict({T_wb[k], Eigen::Vector3d::Zero(), bias}, *next).T_wb.translation();
      v[k] = (T_wb[k + 1].translation() - at_rest) / next->dt();
    } else if (const Preintegration* previous = k > 0 ? from_previous[k] : nullptr) {
      v[k] = predict({T_wb[k - 1], v[k - 1], bias}, *previous).v;  // v[k - 1] came from this interval
    }
  }
  return v;
}

InertialTerms::InertialTerms(const Preintegration& i_to_frame, const InertialState& i, const SE3& T_imu_cam)
    : imu_(i_to_frame), walk_(i_to_frame), i_(i), T_cam_imu_(T_imu_cam.inverse()),
      body_from_camera_(-T_imu_cam.adjoint()) {}

Vector15d InertialTerms::evaluate(const SE3& T_cw, const Eigen::Vector3d& v, const ImuBias& bias, Matrix15d* J) const {
  const ImuPoseParams pose_i = imu_pose_params(i_.T_wb), pose_j = imu_pose_params(body_pose(T_cw));
  const Vector6d b = bias.vector(), b_i = i_.bias.vector();
  // The preintegration is corrected for the frame's bias (the ImuCost's bias block).
  const double* imu_blocks[5] = {pose_i.data(), i_.v.data(), b.data(), pose_j.data(), v.data()};
  Vector15d r;
  Eigen::Matrix<double, 9, 6, Eigen::RowMajor> J_bias;
  Eigen::Matrix<double, 9, 7, Eigen::RowMajor> J_pose;
  Eigen::Matrix<double, 9, 3, Eigen::RowMajor> J_v;
  double* imu_jacobians[5] = {nullptr, nullptr, J_bias.data(), J_pose.data(), J_v.data()};
  imu_.Evaluate(imu_blocks, r.data(), J ? imu_jacobians : nullptr);
  const double* walk_blocks[2] = {b_i.data(), b.data()};
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> J_walk;
  double* walk_jacobians[2] = {nullptr, J_walk.data()};
  walk_.Evaluate(walk_blocks, r.data() + 9, J ? walk_jacobians : nullptr);
  if (J) {
    J->setZero();
    // The pose block's Jacobian w.r.t. the body's tangent sits in its first 6 columns (imu_pose_manifold.h).
    J->block<9, 6>(0, 0) = J_pose.leftCols<6>() * body_from_camera_;
    J->block<9, 3>(0, 6) = J_v;
    J->block<9, 6>(0, 9) = J_bias;
    J->block<6, 6>(9, 9) = J_walk;
  }
  return r;
}

namespace {

struct State {
  SE3 T_cw;
  Eigen::Vector3d v;
  ImuBias bias;

  State plus(const Vector15d& d) const {
    State s{SE3::exp(d.head<6>()) * T_cw, v + d.segment<3>(6), bias};
    s.bias.gyro += d.segment<3>(9);
    s.bias.acc += d.segment<3>(12);
    return s;
  }
};

struct Problem {
  const optim::PoseTerms& visual;
  const InertialTerms& imu;
  const std::vector<bool>& point_out;
  const std::vector<bool>& line_out;

  // The cost (visual under the kernels when robust, plus the IMU rows'); with H and g, the normal
  // equations J' W J and J' W r over the 15-dimensional tangent.
  double evaluate(const State& x, bool robust, Matrix15d* H, Vector15d* g, double* imu_cost = nullptr) const {
    Matrix6d Hv = Matrix6d::Zero();
    Vector6d gv = Vector6d::Zero();
    double cost = visual.evaluate(x.T_cw, point_out, line_out, robust, H ? &Hv : nullptr, H ? &gv : nullptr);
    Matrix15d J;
    const Vector15d r = imu.evaluate(x.T_cw, x.v, x.bias, H ? &J : nullptr);
    if (imu_cost) *imu_cost = r.squaredNorm();
    cost += r.squaredNorm();
    if (H) {
      *H = J.transpose() * J;
      *g = J.transpose() * r;
      H->topLeftCorner<6, 6>() += Hv;
      g->head<6>() += gv;
    }
    return cost;
  }
};

}  // namespace

InertialPoseResult optimize_pose_inertial(const geometry::StereoCamera& cam, const InertialTerms& imu,
                                          const SE3& T_cw_init, const Eigen::Vector3d& v_init, const ImuBias& bias_init,
                                          const std::vector<optim::PosePointTerm>& points,
                                          const std::vector<optim::PoseLineTerm>& lines,
                                          const optim::PoseOnlyOptions& options) {
  const optim::PoseTerms visual(cam, points, lines, options);
  InertialPoseResult res;
  const Problem p{visual, imu, res.visual.point_outlier, res.visual.line_outlier};
  const State x = optim::run_pose_rounds<15>(
      visual, options, State{T_cw_init, v_init, bias_init}, res.visual,
      [&](const State& s, bool robust, Matrix15d* H, Vector15d* g) { return p.evaluate(s, robust, H, g); },
      [](const State& s, const Vector15d& d) { return s.plus(d); }, [](const State& s) { return s.T_cw; });
  Vector15d g;
  p.evaluate(x, /*robust=*/false, &res.information, &g, &res.imu_cost);
  res.visual.T_cw = x.T_cw;
  if (options.covariance) res.visual.covariance = visual.covariance(x.T_cw, res.visual.point_outlier, res.visual.line_outlier);
  res.state = {imu.body_pose(x.T_cw), x.v, x.bias};
  return res;
}

}  // namespace plslam::inertial
