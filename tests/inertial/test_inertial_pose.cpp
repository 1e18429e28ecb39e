// Tracking's pose optimisation with the IMU (inertial/inertial_pose.h): the IMU terms' Jacobian
// over the camera's tangent against central differences, and on a smooth body motion with exact
// IMU samples and a stereo camera off the IMU, the pose, velocity and bias it returns against the
// truth: with rich vision, with vision that leaves a rotation open (the IMU closes it), and with
// gross outliers among the matches.
#include <cmath>
#include <memory>
#include <span>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "inertial/imu_motion.h"
#include "inertial/numeric_jacobian.h"
#include "inertial/stereo_view.h"
#include "plslam/inertial/inertial_pose.h"
#include "plslam/optim/pose_only.h"

namespace plslam::inertial {
namespace {

using geometry::SE3;
using geometry::Vector6d;

// The state of the sinusoid motion at t, its camera pose, and a bias.
struct Truth {
  InertialState state;
  SE3 T_cw;
};

struct Fixture {
  test::SinusoidMotion motion;
  ImuBias true_bias{Eigen::Vector3d(0.004, -0.003, 0.002), Eigen::Vector3d(0.05, -0.08, 0.03)};
  // The left camera 6 cm in front of the IMU, looking along the body's x axis (z forward, y down).
  SE3 T_imu_cam{(Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished(), Eigen::Vector3d(0.06, -0.01, 0.02)};
  geometry::StereoCamera cam{450, 450, 376, 240, 0.11 * 450, 752, 480};
  double t_i = 0.40, t_j = 0.45;
  std::vector<ImuSample> samples = test::sample_motion(motion, 0.3, 0.6, 0.001, true_bias);
  Preintegration pim{samples, t_i, t_j, ImuBias{}, kEurocAdis16448Noise};

  Truth at(double t) const {
    const test::BodyState s = motion.at(t);
    Truth x;
    x.state = {SE3(s.R, s.p), s.v, true_bias};
    x.T_cw = (x.state.T_wb * T_imu_cam).inverse();
    return x;
  }

  // `n` points in view at t_j (stereo_view.h).
  std::vector<optim::PosePointTerm> points(int n, double noise_px, std::uint32_t seed = 1) const {
    return test::stereo_points_in_view(cam, at(t_j).T_cw, n, noise_px, seed);
  }
};

double angle_deg(const SE3& a, const SE3& b) {
  return Eigen::AngleAxisd(a.rotation() * b.rotation().transpose()).angle() * 180 / M_PI;
}

TEST(InertialTerms, JacobianMatchesNumericDifferentiationOverTheCameraTangent) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  const InertialTerms terms(f.pim, i.state, f.T_imu_cam);
  // Away from the truth, so that no block's residual is zero.
  const SE3 T = SE3::exp((Vector6d() << 0.02, -0.01, 0.03, 0.01, -0.02, 0.015).finished()) * j.T_cw;
  const Eigen::Vector3d v = j.state.v + Eigen::Vector3d(0.1, -0.05, 0.02);
  ImuBias b = f.true_bias;
  b.gyro += Eigen::Vector3d(0.002, 0.001, -0.003);
  b.acc += Eigen::Vector3d(-0.02, 0.03, 0.01);
  Matrix15d J;
  terms.evaluate(T, v, b, &J);
  const Eigen::MatrixXd numeric = test::central_differences(
      [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        ImuBias bd = b;
        bd.gyro += d.segment<3>(9);
        bd.acc += d.segment<3>(12);
        return terms.evaluate(SE3::exp(d.head<6>()) * T, v + d.segment<3>(6), bd);
      },
      15, 1e-6);
  for (int block : {0, 6, 9}) {
    const int cols = block == 6 ? 3 : 6;
    const double err = test::relative_error(J.middleCols(block, cols), numeric.middleCols(block, cols));
    EXPECT_LT(err, 1e-6) << "columns " << block << "..";
  }
  EXPECT_GT(J.middleCols(0, 6).norm(), 1.0);  // the pose block is not empty
}

TEST(InertialPrediction, ReachesTheTrueStateAndItsResidualIsZero) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  // Linearised at zero bias, corrected to the true one to first order.
  const InertialState p = predict(i.state, f.pim);
  EXPECT_LT((p.T_wb.translation() - j.state.T_wb.translation()).norm(), 1e-6);
  EXPECT_LT(angle_deg(p.T_wb, j.state.T_wb), 1e-4);
  EXPECT_LT((p.v - j.state.v).norm(), 1e-4);
  const InertialTerms terms(f.pim, i.state, f.T_imu_cam);
  const SE3 T_cw = (p.T_wb * f.T_imu_cam).inverse();
  EXPECT_LT(terms.evaluate(T_cw, p.v, p.bias).head<9>().norm(), 1e-9);
}

// Keyframes 0.1-0.2 s apart through the hand-held-like motion's swings: the seeds from poses and
// IMU are exact where the positions' differences miss by the acceleration times the interval.
TEST(SeedVelocities, ExactFromPosesAndImuWherePositionDifferencesAreOff) {
  const test::SinusoidMotion motion;
  const ImuBias bias{Eigen::Vector3d(0.004, -0.003, 0.002), Eigen::Vector3d(0.05, -0.08, 0.03)};
  const std::vector<double> t = {0.30, 0.45, 0.55, 0.75, 0.85, 1.00, 1.20};
  const auto samples = test::sample_motion(motion, 0.2, 1.3, 0.001, bias);
  std::vector<SE3> T_wb;
  std::vector<std::unique_ptr<Preintegration>> owned;
  std::vector<const Preintegration*> intervals;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const test::BodyState s = motion.at(t[k]);
    T_wb.emplace_back(s.R, s.p);
    if (k > 0) owned.push_back(std::make_unique<Preintegration>(samples, t[k - 1], t[k], bias, kEurocAdis16448Noise));
    intervals.push_back(k > 0 ? owned.back().get() : nullptr);
  }
  const auto v = seed_velocities(T_wb, intervals, bias);
  ASSERT_EQ(v.size(), t.size());
  double worst_difference = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    EXPECT_LT((v[k] - motion.at(t[k]).v).norm(), 2e-3) << "keyframe " << k;
    const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, t.size() - 1);
    const Eigen::Vector3d difference = (T_wb[b].translation() - T_wb[a].translation()) / (t[b] - t[a]);
    worst_difference = std::max(worst_difference, (difference - motion.at(t[k]).v).norm());
  }
  EXPECT_GT(worst_difference, 0.1);  // what the seeds were before: the test tells them apart
  // Gaps in the samples: the pose before one is seeded from the interval before it, and a pose
  // the IMU joins to neither neighbour keeps zero.
  intervals[3] = nullptr;
  intervals[5] = intervals[6] = nullptr;
  const auto w = seed_velocities(T_wb, intervals, bias);
  for (const std::size_t k : {1, 2, 3, 4}) EXPECT_LT((w[k] - motion.at(t[k]).v).norm(), 2e-3) << "keyframe " << k;
  EXPECT_EQ(w[5], Eigen::Vector3d::Zero());
  EXPECT_EQ(w[6], Eigen::Vector3d::Zero());
  EXPECT_THROW(seed_velocities(T_wb, std::span(intervals).first(2), bias), std::invalid_argument);
  // An interval given for the first pose joins it to nothing before it: ignored, so the first
  // pose, without its successor's interval either, keeps zero.
  intervals[0] = intervals[1];
  intervals[1] = nullptr;
  EXPECT_EQ(seed_velocities(T_wb, intervals, bias)[0], Eigen::Vector3d::Zero());
}

TEST(InertialTerms, SmallAtTheTruth) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  const InertialTerms terms(f.pim, i.state, f.T_imu_cam);
  // Exact samples at 1 kHz: the midpoint rule's error over 50 ms is far below the noise.
  EXPECT_LT(terms.evaluate(j.T_cw, j.state.v, f.true_bias).norm(), 0.05);
  // 1 cm off is many sigmas of 50 ms of EuRoC's accelerometer.
  const SE3 off = SE3::exp((Vector6d() << 0.01, 0, 0, 0, 0, 0).finished()) * j.T_cw;
  EXPECT_GT(terms.evaluate(off, j.state.v, f.true_bias).norm(), 10.0);
}

TEST(InertialPose, ConvergesToTheTrueStateFromAFarGuess) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  InertialState fixed = i.state;
  const InertialTerms terms(f.pim, fixed, f.T_imu_cam);
  const auto points = f.points(150, 0.5);
  const SE3 guess = SE3::exp((Vector6d() << 0.05, -0.03, 0.04, 0.02, 0.01, -0.02).finished()) * j.T_cw;
  const auto r = optimize_pose_inertial(f.cam, terms, guess, j.state.v + Eigen::Vector3d(0.3, -0.2, 0.1), ImuBias{},
                                        points, {});
  const double position_error = (r.visual.T_cw.inverse().translation() - j.T_cw.inverse().translation()).norm();
  std::printf("rich vision: %.2e m, %.4f deg, velocity error %.2e m/s, imu cost %.2f\n", position_error,
              angle_deg(r.visual.T_cw, j.T_cw), (r.state.v - j.state.v).norm(), r.imu_cost);
  EXPECT_LT(position_error, 2e-3);
  EXPECT_LT(angle_deg(r.visual.T_cw, j.T_cw), 0.05);
  EXPECT_LT((r.state.v - j.state.v).norm(), 0.02);
  EXPECT_EQ(r.visual.num_point_inliers, 150);
  EXPECT_LT((r.state.T_wb.translation() - j.state.T_wb.translation()).norm(), 2e-3);
  // Every direction of the 15 is held (the bias by its walk from state i).
  const Eigen::SelfAdjointEigenSolver<Matrix15d> eig(r.information);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

TEST(InertialPose, TheImuClosesARotationThatTwoPointsLeaveOpen) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  const InertialTerms terms(f.pim, i.state, f.T_imu_cam);
  const auto points = f.points(2, 0.0);
  // Turned by 2 degrees about the line through the two points (in the camera frame): they project
  // where they did, and vision alone cannot tell.
  const Eigen::Vector3d a = j.T_cw * points[0].world, b = j.T_cw * points[1].world;
  const Eigen::Vector3d axis = (b - a).normalized();
  const SE3 about_a = SE3(Eigen::Matrix3d::Identity(), a) *
                      SE3(Eigen::AngleAxisd(2.0 * M_PI / 180, axis).toRotationMatrix(), Eigen::Vector3d::Zero()) *
                      SE3(Eigen::Matrix3d::Identity(), -a);
  const SE3 guess = about_a.inverse() * j.T_cw;
  ASSERT_NEAR(angle_deg(guess, j.T_cw), 2.0, 1e-6);
  const auto visual_only = optim::optimize_pose(f.cam, guess, points, {});
  const auto r = optimize_pose_inertial(f.cam, terms, guess, j.state.v, f.true_bias, points, {});
  std::printf("two points: pose-only %.3f deg off, with the IMU %.5f deg\n", angle_deg(visual_only.T_cw, j.T_cw),
              angle_deg(r.visual.T_cw, j.T_cw));
  EXPECT_GT(angle_deg(visual_only.T_cw, j.T_cw), 1.0);
  EXPECT_LT(angle_deg(r.visual.T_cw, j.T_cw), 0.01);
  EXPECT_LT((r.visual.T_cw.inverse().translation() - j.T_cw.inverse().translation()).norm(), 1e-3);
}

TEST(InertialPose, GrossOutliersAreFlaggedAsInThePoseOnlyOptimisation) {
  const Fixture f;
  const Truth i = f.at(f.t_i), j = f.at(f.t_j);
  const InertialTerms terms(f.pim, i.state, f.T_imu_cam);
  auto points = f.points(100, 0.5, 7);
  for (std::size_t k = 0; k < points.size(); k += 10) points[k].obs.measurement += Eigen::Vector3d(40, -25, 40);
  const auto r = optimize_pose_inertial(f.cam, terms, j.T_cw, j.state.v, f.true_bias, points, {});
  for (std::size_t k = 0; k < points.size(); ++k) EXPECT_EQ(r.visual.point_outlier[k], k % 10 == 0) << k;
  EXPECT_EQ(r.visual.num_point_inliers, 90);
  EXPECT_LT((r.visual.T_cw.inverse().translation() - j.T_cw.inverse().translation()).norm(), 2e-3);
}

}  // namespace
}  // namespace plslam::inertial
