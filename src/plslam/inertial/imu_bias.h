#pragma once
// The IMU's slowly varying measurement offsets: measured = true + bias + noise, for the gyro and
// the accelerometer alike. In a Ceres problem a bias is one 6-double block [bg; ba].
#include <Eigen/Core>

#include "plslam/geometry/se3.h"

namespace plslam::inertial {

struct ImuBias {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();  // rad/s
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();   // m/s^2

  // [bg; ba], the layout of a bias parameter block.
  geometry::Vector6d vector() const {
    geometry::Vector6d b;
    b << gyro, acc;
    return b;
  }
  static ImuBias from_vector(const double* b) {
    return {Eigen::Vector3d(b[0], b[1], b[2]), Eigen::Vector3d(b[3], b[4], b[5])};
  }
};

}  // namespace plslam::inertial
