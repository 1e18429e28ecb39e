// NEES of frame-to-frame motions: the motion covariance formula against Monte Carlo, and the mean
// NEES of consistent, overconfident and underconfident covariances.
#include <random>

#include <gtest/gtest.h>

#include "plslam/eval/motion_nees.h"

namespace plslam::eval {
namespace {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

Vector6d gaussian(std::mt19937& rng, const Matrix6d& S) {
  std::normal_distribution<double> g(0, 1);
  Vector6d z;
  for (int k = 0; k < 6; ++k) z(k) = g(rng);
  return Eigen::LLT<Matrix6d>(S).matrixL() * z;
}

Matrix6d random_covariance(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Matrix6d A;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) A(r, c) = u(rng);
  }
  Matrix6d S = A * A.transpose() + Matrix6d::Identity();
  S.topRows<3>() *= 1e-2;  // cm in translation, 10 mrad in rotation
  S.leftCols<3>() *= 1e-2;
  S.bottomRows<3>() *= 1e-2;
  S.rightCols<3>() *= 1e-2;
  return S;
}

SE3 random_motion(std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  Vector6d xi;
  for (int k = 0; k < 3; ++k) xi(k) = 0.5 * g(rng);
  for (int k = 3; k < 6; ++k) xi(k) = 0.3 * g(rng);
  return SE3::exp(xi);
}

TEST(MotionNees, MotionCovarianceMatchesMonteCarlo) {
  std::mt19937 rng(3);
  const SE3 T1 = random_motion(rng), T12 = random_motion(rng), T2 = T1 * T12;
  const Matrix6d S1 = random_covariance(rng) * 1e-2, S2 = random_covariance(rng) * 1e-2;
  Matrix6d empirical = Matrix6d::Zero();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const SE3 e1 = T1 * SE3::exp(gaussian(rng, S1)), e2 = T2 * SE3::exp(gaussian(rng, S2));
    const Vector6d xi = (T12.inverse() * (e1.inverse() * e2)).log();  // the truth's error, T_12 = est exp(xi)
    empirical += xi * xi.transpose() / n;
  }
  const Matrix6d predicted = motion_covariance(T12, S1, S2);
  EXPECT_LT((empirical - predicted).norm(), 0.03 * predicted.norm()) << empirical << "\n\n" << predicted;
}

// Poses with errors drawn from S_true, scored with S_told: the mean NEES is 6 S_true / S_told.
double mean_nees(double told_over_true, unsigned seed) {
  std::mt19937 rng(seed);
  Trajectory gt;
  std::vector<CovariantPose> est;
  SE3 T;
  for (int i = 0; i < 3000; ++i) {
    T = T * random_motion(rng);
    const Matrix6d S = random_covariance(rng) * 1e-2;
    gt.push_back({0.1 * i, T.isometry()});
    // T_true = T_est exp(xi): T_est = T_true exp(-xi)
    est.push_back({0.1 * i, T * SE3::exp(-gaussian(rng, S)), told_over_true * S});
  }
  const auto r = motion_nees(gt, est, 0.15);
  EXPECT_EQ(r.nees.size(), 2999u);
  return r.mean;
}

TEST(MotionNees, ConsistentCovarianceAveragesSixAndScalesWithIt) {
  EXPECT_NEAR(mean_nees(1.0, 1), 6.0, 0.3);
  EXPECT_NEAR(mean_nees(4.0, 2), 1.5, 0.1);    // too large: under 6
  EXPECT_NEAR(mean_nees(0.25, 3), 24.0, 1.2);  // overconfident: over 6
}

TEST(MotionNees, SkipsGapsPosesWithoutCovarianceOrGroundTruth) {
  Trajectory gt;
  std::vector<CovariantPose> est;
  for (int i = 0; i < 6; ++i) {
    if (i != 4) gt.push_back({0.1 * i, Eigen::Isometry3d::Identity()});
    if (i != 2) est.push_back({0.1 * i, SE3(), Matrix6d::Identity() * 1e-4});
  }
  est[0].covariance.setZero();  // frame 0: no covariance
  // Pairs (t): 0-0.1 no covariance, 0.1-0.3 a gap over 0.15 s, 0.3-0.4 no ground truth at 0.4,
  // 0.4-0.5 likewise: none scored.
  EXPECT_TRUE(motion_nees(gt, est, 0.15).nees.empty());
  EXPECT_EQ(motion_nees(gt, est, 0.25).nees.size(), 1u);  // 0.1-0.3 now
  EXPECT_DOUBLE_EQ(motion_nees(gt, est, 0.25).nees[0], 0.0);  // exact motion
}

}  // namespace
}  // namespace plslam::eval
