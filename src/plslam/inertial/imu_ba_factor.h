#pragma once
// The IMU between two keyframes that follow each other in time, as a factor of the bundle
// adjustment (optim/ba_keyframe_factor.h): the preintegrated residual between them
// (imu_residual.h, its deltas corrected for keyframe i's bias) and the bias random walk from i to
// j, 15 whitened rows. Each keyframe's extra state is the IMU's [v (world); bg; ba]. The poses are
// the left cameras' T_cw, perturbed as the reprojection errors are; the body follows as
// T_wb = T_cw^-1 T_imu_cam^-1, whose tangent moves by -Ad(T_imu_cam) per camera delta
// (inertial_pose.h).
#include <array>

#include "plslam/inertial/bias_random_walk_residual.h"
#include "plslam/inertial/imu_bias.h"
#include "plslam/inertial/imu_residual.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/optim/ba_keyframe_factor.h"

namespace plslam::inertial {

// A keyframe's extra state in the BA: [v; bg; ba].
optim::Vector9d ba_extra_state(const Eigen::Vector3d& v, const ImuBias& bias);
Eigen::Vector3d velocity_of(const optim::Vector9d& extra);
ImuBias bias_of(const optim::Vector9d& extra);

class ImuBaFactor final : public optim::BaKeyframeFactor {
 public:
  // `i_to_j` from keyframe i's time to j's; `T_imu_cam` places the left camera in the IMU frame.
  // Throws std::invalid_argument as ImuCost and BiasRandomWalkCost do.
  ImuBaFactor(int keyframe_i, int keyframe_j, const Preintegration& i_to_j, const geometry::SE3& T_imu_cam);

  std::span<const int> keyframes() const override { return keyframes_; }
  int rows() const override { return 15; }
  Eigen::VectorXd evaluate(std::span<const geometry::SE3> T_cw, std::span<const optim::Vector9d> extra,
                           Eigen::MatrixXd* J) const override;

 private:
  std::array<int, 2> keyframes_;
  ImuCost imu_;
  BiasRandomWalkCost walk_;
  geometry::SE3 T_cam_imu_;
  geometry::Matrix6d body_from_camera_;  // -Ad(T_imu_cam)
};

}  // namespace plslam::inertial
