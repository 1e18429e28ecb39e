#pragma once
// Factors of a bundle adjustment that tie keyframes to each other directly, with no landmark in
// between: the IMU's preintegrated motion between consecutive keyframes (inertial/imu_ba_factor.h)
// is one. Such a factor may also involve a keyframe's extra state, 9 Euclidean parameters that the
// factor gives a meaning to (the IMU's velocity and biases). The Schur backend adds these factors
// to the reduced camera system as they are: nothing is eliminated through them.
#include <span>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"

namespace plslam::optim {

using Vector9d = Eigen::Matrix<double, 9, 1>;

class BaKeyframeFactor {
 public:
  // Columns of the Jacobian per keyframe: the pose's tangent (T_cw <- exp(delta) T_cw, delta =
  // (translation, rotation), as the reprojection errors) and then the extra state's 9.
  static constexpr int kColumnsPerKeyframe = 15;

  virtual ~BaKeyframeFactor() = default;
  // Indices into the problem's keyframes.
  virtual std::span<const int> keyframes() const = 0;
  virtual int rows() const = 0;
  // The whitened residual at its keyframes' poses and extra states (in the order of keyframes());
  // with J, also its Jacobian, rows() x (15 per keyframe). The cost is 1/2 |r|^2, no robust kernel.
  virtual Eigen::VectorXd evaluate(std::span<const geometry::SE3> T_cw, std::span<const Vector9d> extra,
                                   Eigen::MatrixXd* J) const = 0;
};

}  // namespace plslam::optim
