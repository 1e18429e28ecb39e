#include "plslam/inertial/imu_ba_factor.h"

#include <stdexcept>

#include "plslam/inertial/imu_pose_manifold.h"

namespace plslam::inertial {

optim::Vector9d ba_extra_state(const Eigen::Vector3d& v, const ImuBias& bias) {
  optim::Vector9d x;
  x << v, bias.gyro, bias.acc;
  return x;
}

Eigen::Vector3d velocity_of(const optim::Vector9d& extra) { return extra.head<3>(); }

ImuBias bias_of(const optim::Vector9d& extra) { return ImuBias::from_vector(extra.data() + 3); }

ImuBaFactor::ImuBaFactor(int keyframe_i, int keyframe_j, const Preintegration& i_to_j, const geometry::SE3& T_imu_cam)
    : keyframes_{keyframe_i, keyframe_j}, imu_(i_to_j), walk_(i_to_j), T_cam_imu_(T_imu_cam.inverse()),
      body_from_camera_(-T_imu_cam.adjoint()) {}

Eigen::VectorXd ImuBaFactor::evaluate(std::span<const geometry::SE3> T_cw, std::span<const optim::Vector9d> extra,
                                      Eigen::MatrixXd* J) const {
  if (T_cw.size() != 2 || extra.size() != 2) throw std::invalid_argument("ImuBaFactor: two keyframes");
  const ImuPoseParams pose_i = imu_pose_params(T_cw[0].inverse() * T_cam_imu_);
  const ImuPoseParams pose_j = imu_pose_params(T_cw[1].inverse() * T_cam_imu_);
  const Eigen::Vector3d v_i = extra[0].head<3>(), v_j = extra[1].head<3>();
  const geometry::Vector6d b_i = extra[0].tail<6>(), b_j = extra[1].tail<6>();
  Eigen::VectorXd r(15);
  Eigen::Matrix<double, 9, 7, Eigen::RowMajor> J_pose_i, J_pose_j;
  Eigen::Matrix<double, 9, 3, Eigen::RowMajor> J_v_i, J_v_j;
  Eigen::Matrix<double, 9, 6, Eigen::RowMajor> J_bias;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> J_walk_i, J_walk_j;
  const double* imu_blocks[5] = {pose_i.data(), v_i.data(), b_i.data(), pose_j.data(), v_j.data()};
  double* imu_jacobians[5] = {J_pose_i.data(), J_v_i.data(), J_bias.data(), J_pose_j.data(), J_v_j.data()};
  imu_.Evaluate(imu_blocks, r.data(), J ? imu_jacobians : nullptr);
  const double* walk_blocks[2] = {b_i.data(), b_j.data()};
  double* walk_jacobians[2] = {J_walk_i.data(), J_walk_j.data()};
  walk_.Evaluate(walk_blocks, r.data() + 9, J ? walk_jacobians : nullptr);
  if (J) {
    // Columns: keyframe i [delta (6); v (3); bias (6)], then keyframe j's. The pose blocks'
    // Jacobians over the body's tangent are their first 6 columns (imu_pose_manifold.h).
    J->setZero(15, 30);
    J->block<9, 6>(0, 0) = J_pose_i.leftCols<6>() * body_from_camera_;
    J->block<9, 3>(0, 6) = J_v_i;
    J->block<9, 6>(0, 9) = J_bias;
    J->block<9, 6>(0, 15) = J_pose_j.leftCols<6>() * body_from_camera_;
    J->block<9, 3>(0, 21) = J_v_j;
    J->block<6, 6>(9, 9) = J_walk_i;
    J->block<6, 6>(9, 24) = J_walk_j;
  }
  return r;
}

}  // namespace plslam::inertial
