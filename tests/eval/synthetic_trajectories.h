#pragma once
// Trajectories with errors known in closed form, shared by the eval tests.
#include <cmath>

#include <Eigen/Geometry>

#include "plslam/core/types.h"

namespace plslam::eval::test {

inline Eigen::Isometry3d make_pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

inline Eigen::Matrix3d rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// A rising helix with a turning orientation: non-degenerate for alignment in 3D.
inline Trajectory helix(int n, double dt = 0.1) {
  Trajectory traj;
  for (int i = 0; i < n; ++i) {
    const double a = 0.05 * i;
    traj.push_back({i * dt, make_pose(rot(a, {0.1, 0.2, 1.0}),
                                      {3.0 * std::cos(a), 2.0 * std::sin(a), 0.02 * i})});
  }
  return traj;
}

// A straight line along x, v metres per frame, identity orientation.
inline Trajectory straight_line(int n, double v) {
  Trajectory traj;
  for (int i = 0; i < n; ++i) traj.push_back({i * 0.1, make_pose(Eigen::Matrix3d::Identity(), {i * v, 0, 0})});
  return traj;
}

}  // namespace plslam::eval::test
