#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "plslam/geometry/se3.h"

namespace plslam::geometry {
namespace {

Eigen::Vector3d random_axis(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
}

Vector6d random_xi(std::mt19937& rng, double angle) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vector6d xi;
  xi << 3.0 * g(rng), 3.0 * g(rng), 3.0 * g(rng), angle * random_axis(rng);
  return xi;
}

TEST(So3, ExpIsRotationAndMatchesEigenAngleAxis) {
  std::mt19937 rng(1);
  for (const double angle : {0.0, 1e-12, 1e-7, 1e-4, 0.3, 2.0, M_PI - 1e-6, M_PI}) {
    const Eigen::Vector3d axis = random_axis(rng);
    const Eigen::Matrix3d R = so3_exp(angle * axis);
    const Eigen::Matrix3d ref = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((R - ref).norm(), 1e-14) << angle;
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  }
}

TEST(So3, LogRoundTripIncludingNearZeroAndNearPi) {
  std::mt19937 rng(2);
  const double angles[] = {0.0, 1e-15, 1e-10, 1e-6, 1e-3, 0.5, 1.5, 3.0, M_PI - 1e-4,
                           M_PI - 1e-8, M_PI - 1e-12};
  for (const double angle : angles) {
    for (int rep = 0; rep < 50; ++rep) {
      const Eigen::Vector3d phi = angle * random_axis(rng);
      const Eigen::Vector3d back = so3_log(so3_exp(phi));
      // Absolute error: near pi the axis is recovered to ~sqrt(eps)-free precision by the
      // quaternion route; with the acos route it degrades to ~1e-8.
      EXPECT_LT((back - phi).norm(), 1e-9 * std::max(1.0, angle)) << "angle " << angle;
    }
  }
  // Exactly pi: phi and -phi are the same rotation; either is a correct log.
  const Eigen::Vector3d phi = M_PI * Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d back = so3_log(so3_exp(phi));
  EXPECT_NEAR(back.norm(), M_PI, 1e-12);
  EXPECT_LT((so3_exp(back) - so3_exp(phi)).norm(), 1e-12);
}

TEST(So3, LeftJacobianMatchesFiniteDifferencesAndInverse) {
  std::mt19937 rng(3);
  for (const double angle : {1e-9, 1e-5, 1e-3, 0.05, 0.7, 2.5, 3.1}) {
    const Eigen::Vector3d phi = angle * random_axis(rng);
    const Eigen::Matrix3d J = so3_left_jacobian(phi);
    // exp(phi + d) exp(phi)^-1 = exp(J d)
    Eigen::Matrix3d num;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(k);
      const Eigen::Vector3d p = so3_log(so3_exp(phi + d) * so3_exp(phi).transpose());
      const Eigen::Vector3d m = so3_log(so3_exp(phi - d) * so3_exp(phi).transpose());
      num.col(k) = (p - m) / (2 * h);
    }
    EXPECT_LT((J - num).norm(), 1e-8) << angle;
    EXPECT_LT((so3_left_jacobian_inverse(phi) * J - Eigen::Matrix3d::Identity()).norm(), 1e-12)
        << angle;
  }
}

TEST(Se3, ExpLogRoundTrip) {
  std::mt19937 rng(4);
  for (const double angle : {0.0, 1e-14, 1e-9, 1e-5, 0.02, 0.09, 0.11, 1.0, 3.0, M_PI - 1e-6}) {
    for (int rep = 0; rep < 50; ++rep) {
      const Vector6d xi = random_xi(rng, angle);
      const Vector6d back = SE3::exp(xi).log();
      EXPECT_LT((back - xi).norm(), 1e-9 * std::max(1.0, xi.norm())) << "angle " << angle;
      // And the group element round trip, exp(log(T)) == T.
      const SE3 T = SE3::exp(xi);
      const SE3 T2 = SE3::exp(T.log());
      EXPECT_LT((T.matrix() - T2.matrix()).norm(), 1e-9);
    }
  }
}

TEST(Se3, CompositionInverseActionAndConversions) {
  std::mt19937 rng(5);
  for (int rep = 0; rep < 100; ++rep) {
    const SE3 A = SE3::exp(random_xi(rng, 2.0));
    const SE3 B = SE3::exp(random_xi(rng, 1.0));
    const Eigen::Vector3d p(1.0, -2.0, 0.5);
    EXPECT_LT(((A * B).matrix() - A.matrix() * B.matrix()).norm(), 1e-12);
    EXPECT_LT(((A * A.inverse()).matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-12);
    EXPECT_LT(((A * B) * p - A * (B * p)).norm(), 1e-12);
    EXPECT_LT((SE3::from_matrix(A.matrix()).matrix() - A.matrix()).norm(), 1e-12);
    EXPECT_LT((SE3(A.quaternion(), A.translation()).matrix() - A.matrix()).norm(), 1e-12);
    EXPECT_LT((SE3(A.isometry()).matrix() - A.matrix()).norm(), 1e-12);
    EXPECT_NEAR(A.quaternion().norm(), 1.0, 1e-15);
  }
}

TEST(Se3, AdjointConjugatesTangentVectors) {
  std::mt19937 rng(6);
  for (int rep = 0; rep < 100; ++rep) {
    const SE3 T = SE3::exp(random_xi(rng, 2.5));
    const Vector6d xi = random_xi(rng, 0.8);
    const SE3 lhs = SE3::exp(T.adjoint() * xi);
    const SE3 rhs = T * SE3::exp(xi) * T.inverse();
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-10);
  }
}

// d/d(delta) of log(exp(xi + delta) exp(xi)^-1) = J_l(xi), and the inverse / right versions.
TEST(Se3, JacobiansMatchFiniteDifferences) {
  std::mt19937 rng(7);
  int checked = 0;
  for (const double angle : {1e-8, 1e-4, 0.01, 0.099, 0.101, 0.5, 1.7, 3.0}) {
    for (int rep = 0; rep < 150; ++rep, ++checked) {
      const Vector6d xi = random_xi(rng, angle);
      const SE3 T = SE3::exp(xi);
      Matrix6d num_l, num_r;
      const double h = 1e-6;
      for (int k = 0; k < 6; ++k) {
        const Vector6d d = h * Vector6d::Unit(k);
        num_l.col(k) = ((SE3::exp(xi + d) * T.inverse()).log() - (SE3::exp(xi - d) * T.inverse()).log()) / (2 * h);
        num_r.col(k) = ((T.inverse() * SE3::exp(xi + d)).log() - (T.inverse() * SE3::exp(xi - d)).log()) / (2 * h);
      }
      const Matrix6d Jl = se3_left_jacobian(xi);
      const double scale = std::max(1.0, Jl.norm());
      EXPECT_LT((Jl - num_l).norm(), 1e-6 * scale) << "angle " << angle;
      EXPECT_LT((se3_left_jacobian(-xi) - num_r).norm(), 1e-6 * scale) << "angle " << angle;
      EXPECT_LT((se3_left_jacobian_inverse(xi) * Jl - Matrix6d::Identity()).norm(), 1e-9);
      EXPECT_LT((se3_right_jacobian_inverse(xi) * se3_left_jacobian(-xi) - Matrix6d::Identity()).norm(), 1e-9);
    }
  }
  EXPECT_GE(checked, 1000);
}

}  // namespace
}  // namespace plslam::geometry
