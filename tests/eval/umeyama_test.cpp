// Umeyama alignment recovers known rigid and similarity transforms exactly.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <stdexcept>

#include "plslam/geometry/umeyama.h"

namespace plslam::geometry {
namespace {

Eigen::Matrix3Xd random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

Eigen::Matrix3d rotation(double angle, Eigen::Vector3d axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

TEST(Umeyama, RecoversKnownSE3) {
  const Eigen::Matrix3Xd src = random_points(50, 1);
  const Eigen::Matrix3d R = rotation(2.1, {0.3, -1.0, 0.5});
  const Eigen::Vector3d t(4.0, -2.0, 7.5);
  const Eigen::Matrix3Xd dst = (R * src).colwise() + t;
  const auto a = umeyama(src, dst, false);
  EXPECT_LT((a.R - R).norm(), 1e-12);
  EXPECT_LT((a.t - t).norm(), 1e-12);
  EXPECT_EQ(a.s, 1.0);
  EXPECT_LT((a.apply(src.col(3)) - dst.col(3)).norm(), 1e-12);
}

TEST(Umeyama, RecoversKnownSim3) {
  const Eigen::Matrix3Xd src = random_points(20, 2);
  const Eigen::Matrix3d R = rotation(-0.7, {1.0, 2.0, 3.0});
  const Eigen::Vector3d t(-1.0, 0.25, 3.0);
  const double s = 2.75;
  const Eigen::Matrix3Xd dst = (s * R * src).colwise() + t;
  const auto a = umeyama(src, dst, true);
  EXPECT_LT((a.R - R).norm(), 1e-12);
  EXPECT_LT((a.t - t).norm(), 1e-11);
  EXPECT_NEAR(a.s, s, 1e-12);
}

TEST(Umeyama, RotationByPiAndPlanarPointsStayProperRotations) {
  // Points in a plane give a rank-2 covariance; a half turn is the hardest case for the sign fix.
  Eigen::Matrix3Xd src = random_points(30, 3);
  src.row(2).setZero();
  const Eigen::Matrix3d R = rotation(M_PI, {0.0, 1.0, 0.0});
  const Eigen::Matrix3Xd dst = R * src;
  const auto a = umeyama(src, dst, false);
  EXPECT_NEAR(a.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((a.R - R).norm(), 1e-10);
}

TEST(Umeyama, NeverReturnsAReflection) {
  // The mirror image is best fit by a reflection; Umeyama must return the best rotation instead.
  const Eigen::Matrix3Xd src = random_points(10, 4);
  Eigen::Matrix3Xd dst = src;
  dst.row(0) *= -1.0;
  const auto a = umeyama(src, dst, false);
  EXPECT_NEAR(a.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((a.R.transpose() * a.R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Umeyama, ScaleOnlyNoiseLeavesAnOptimum) {
  // With noise, the solution must be a least-squares optimum: perturbing it raises the cost.
  const Eigen::Matrix3Xd src = random_points(40, 5);
  Eigen::Matrix3Xd dst = (1.5 * rotation(0.4, {0, 0, 1}) * src).colwise() + Eigen::Vector3d(1, 2, 3);
  dst += 0.05 * random_points(40, 6);
  const auto a = umeyama(src, dst, true);
  auto cost = [&](const AlignmentResult& r) {
    double c = 0.0;
    for (int i = 0; i < src.cols(); ++i) c += (dst.col(i) - r.apply(src.col(i))).squaredNorm();
    return c;
  };
  const double best = cost(a);
  for (int k = 0; k < 7; ++k) {
    AlignmentResult b = a;
    const double e = 1e-4;
    if (k < 3) b.t(k) += e;
    else if (k < 6) b.R = rotation(e, Eigen::Vector3d::Unit(k - 3)) * b.R;
    else b.s += e;
    EXPECT_GT(cost(b), best) << "perturbation " << k;
  }
}

TEST(Umeyama, RejectsBadInput) {
  EXPECT_THROW(umeyama(random_points(2, 7), random_points(2, 8), false), std::invalid_argument);
  EXPECT_THROW(umeyama(random_points(5, 7), random_points(4, 8), false), std::invalid_argument);
  const Eigen::Matrix3Xd same = Eigen::Matrix3Xd::Ones(3, 5);
  EXPECT_THROW(umeyama(same, random_points(5, 9), true), std::invalid_argument);
}

}  // namespace
}  // namespace plslam::geometry
