#pragma once
// The gauge of a visual-inertial bundle adjustment over a whole map. Gravity makes roll and pitch
// observable: only the position and the heading about gravity (world z) are free, 4 DoF, not 6.
// Holding the first keyframe's whole pose fixed keeps its tilt where the IMU's initialisation put
// it (0.19 deg off on one render), and the IMU factors then bend the map towards that error. This
// factor holds the keyframe's camera centre and heading where they were and leaves its roll and
// pitch to the IMU (ORB-SLAM3's inertial maps have the same 4-DoF gauge).
#include <array>

#include "plslam/geometry/se3.h"
#include "plslam/optim/ba_keyframe_factor.h"

namespace plslam::inertial {

class GaugePriorFactor final : public optim::BaKeyframeFactor {
 public:
  // Holds keyframe `keyframe` at `T_cw`'s camera centre and heading, within `sigma_m` metres and
  // `sigma_rad` radians. The gauge has no other cost on it, so the weights only set how quickly the
  // solver settles there. Throws std::invalid_argument on a sigma that is not positive.
  GaugePriorFactor(int keyframe, const geometry::SE3& T_cw, double sigma_m = 1e-4, double sigma_rad = 1e-5);

  std::span<const int> keyframes() const override { return keyframes_; }
  int rows() const override { return 4; }
  // Rows: the camera centre's offset (3), then the z component of the world-frame rotation from the
  // held orientation to the current one; whitened.
  Eigen::VectorXd evaluate(std::span<const geometry::SE3> T_cw, std::span<const optim::Vector9d> extra,
                           Eigen::MatrixXd* J) const override;

 private:
  std::array<int, 1> keyframes_;
  Eigen::Vector3d centre_;
  Eigen::Matrix3d R_cw_;  // the held orientation, as T_cw's rotation
  double w_position_, w_heading_;
};

}  // namespace plslam::inertial
