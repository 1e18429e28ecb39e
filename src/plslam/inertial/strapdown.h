#pragma once
// Strapdown integration: the IMU's pose and velocity in a gravity-aligned world, dead-reckoned from
// its samples alone. Classical fourth-order Runge-Kutta over pairs of sample intervals, whose
// middle sample is the exact mid-stage value, so no measurement is interpolated: the error falls
// with the 4th power of the sample period on smooth motion (it checks the synthetic IMU against
// its ground truth, and carries a pose where vision has none).
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "plslam/core/imu.h"

namespace plslam::inertial {

struct NavState {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world from IMU
  Eigen::Vector3d v = Eigen::Vector3d::Zero();      // world frame
  Eigen::Vector3d p = Eigen::Vector3d::Zero();      // world frame
};

// Integrates `state`, valid at samples[first].t, to samples[last].t (first <= last) with the
// given biases subtracted; gravity points along -z with magnitude kGravity. An odd number of
// intervals ends with one trapezoidal step.
NavState integrate_strapdown(const NavState& state, const std::vector<ImuSample>& samples, std::size_t first,
                             std::size_t last, const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                             const Eigen::Vector3d& acc_bias = Eigen::Vector3d::Zero());

}  // namespace plslam::inertial
