// The time-scaled constant-velocity prediction against exact synthetic motion: a camera moving
// along a fixed screw (constant twist per second), sampled at irregular times.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "plslam/tracking/motion_model.h"

namespace plslam::tracking {
namespace {

using geometry::SE3;
using geometry::Vector6d;

// T_cw at time t for a camera whose T_cw changes by exp(t · xi) (xi per second).
SE3 pose_at(const Vector6d& xi, double t, const SE3& T0) { return SE3::exp(t * xi) * T0; }

double pose_error(const SE3& a, const SE3& b) { return (a.inverse() * b).log().norm(); }

Vector6d twist() {
  Vector6d xi;
  xi << 1.2, -0.3, 8.0, 0.05, 0.4, -0.1;  // m/s and rad/s: a car turning at 23 deg/s
  return xi;
}

TEST(MotionModel, PredictsExactlyAcrossADroppedFrame) {
  const SE3 T0(Eigen::Quaterniond(0.9, 0.1, -0.2, 0.3), Eigen::Vector3d(1, 2, 3));
  const Vector6d xi = twist();
  // Frames at 0.0 and 0.1 s give the velocity; the next frame comes 0.2 s later (one dropped).
  const SE3 a = pose_at(xi, 0.0, T0), b = pose_at(xi, 0.1, T0), c = pose_at(xi, 0.3, T0);
  const SE3 velocity = b * a.inverse();
  const SE3 predicted = predict_pose(velocity, 0.1, 0.2, b);
  EXPECT_LT(pose_error(predicted, c), 1e-9);
  // The frame-count model (velocity applied once) is off by a whole interval's motion.
  EXPECT_GT(pose_error((velocity * b).normalized(), c), 0.5);
}

TEST(MotionModel, ScalesToShorterAndIrregularIntervals) {
  const SE3 T0;
  const Vector6d xi = twist();
  for (double dt : {0.03, 0.05, 0.1037, 0.25, 1.0}) {
    const SE3 a = pose_at(xi, 0.7, T0), b = pose_at(xi, 0.8, T0);
    const SE3 predicted = predict_pose(b * a.inverse(), 0.1, dt, b);
    EXPECT_LT(pose_error(predicted, pose_at(xi, 0.8 + dt, T0)), 1e-9) << "dt " << dt;
  }
}

TEST(MotionModel, EqualIntervalsKeepTheMotionUnchanged) {
  const SE3 v = SE3::exp(0.1 * twist());
  const SE3 s = scale_motion(v, 0.1, 0.1);
  EXPECT_EQ(s.translation(), v.translation());
  EXPECT_EQ(s.rotation(), v.rotation());
}

TEST(MotionModel, BrokenTimesKeepTheMotionAsItIs) {
  const SE3 v = SE3::exp(0.1 * twist());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (auto [vdt, dt] : {std::pair{0.0, 0.1}, {0.1, 0.0}, {0.1, -0.1}, {nan, 0.1}, {0.1, nan}}) {
    const SE3 s = scale_motion(v, vdt, dt);
    EXPECT_LT(pose_error(s, v), 1e-15) << vdt << " " << dt;
  }
}

TEST(MotionModel, HalfTheTimeIsHalfTheScrew) {
  const SE3 v = SE3::exp(0.1 * twist());
  const SE3 half = scale_motion(v, 0.1, 0.05);
  EXPECT_LT(pose_error(half * half, v), 1e-12);
}

}  // namespace
}  // namespace plslam::tracking
