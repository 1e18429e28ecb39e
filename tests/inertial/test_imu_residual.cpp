// The IMU residual and the bias random-walk residual as Ceres costs: zero at the true states,
// every analytic Jacobian block against central differences on the manifold, the pose manifold
// itself, and a small Ceres solve through it.
#include <array>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>

#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "inertial/imu_motion.h"
#include "inertial/numeric_jacobian.h"
#include "plslam/inertial/bias_random_walk_residual.h"
#include "plslam/inertial/imu_pose_manifold.h"
#include "plslam/inertial/imu_residual.h"

namespace plslam::inertial {
namespace {

using geometry::SE3;
using geometry::Vector6d;

// The five parameter blocks of an ImuCost, in its order.
struct ImuStates {
  ImuPoseParams pose_i{};
  std::array<double, 3> v_i{};
  std::array<double, 6> bias_i{};
  ImuPoseParams pose_j{};
  std::array<double, 3> v_j{};

  std::array<double*, 5> blocks() {
    return {pose_i.data(), v_i.data(), bias_i.data(), pose_j.data(), v_j.data()};
  }
};

constexpr std::array<int, 5> kBlockSizes = {7, 3, 6, 7, 3};
constexpr std::array<int, 5> kTangentSizes = {6, 3, 6, 6, 3};

ImuStates true_states(const test::SinusoidMotion& motion, double t_i, double t_j,
                      const ImuBias& bias) {
  const test::BodyState si = motion.at(t_i), sj = motion.at(t_j);
  ImuStates x;
  x.pose_i = imu_pose_params(SE3(si.R, si.p));
  x.pose_j = imu_pose_params(SE3(sj.R, sj.p));
  std::copy(si.v.data(), si.v.data() + 3, x.v_i.begin());
  std::copy(sj.v.data(), sj.v.data() + 3, x.v_j.begin());
  const Vector6d b = bias.vector();
  std::copy(b.data(), b.data() + 6, x.bias_i.begin());
  return x;
}

Vector9d evaluate(const ImuCost& cost, ImuStates x) {
  const auto blocks = x.blocks();
  Vector9d r;
  EXPECT_TRUE(cost.Evaluate(blocks.data(), r.data(), nullptr));
  return r;
}

// Block k moved by the tangent vector d: poses through ImuPoseManifold, the rest additively.
ImuStates moved(ImuStates x, int k, const Eigen::VectorXd& d) {
  double* block = x.blocks()[static_cast<size_t>(k)];
  if (kBlockSizes[static_cast<size_t>(k)] == 7) {
    ImuPoseParams out{};
    ImuPoseManifold().Plus(block, d.data(), out.data());
    std::copy(out.begin(), out.end(), block);
  } else {
    for (int c = 0; c < d.size(); ++c) block[c] += d(c);
  }
  return x;
}

struct ResidualFixture {
  test::SinusoidMotion motion;
  ImuBias true_bias{Eigen::Vector3d(0.01, -0.02, 0.015), Eigen::Vector3d(0.1, -0.05, 0.2)};
  double t_i = 0.2013, t_j = 0.4521;
};

TEST(ImuCost, ZeroAtTheTrueStatesWithTheTrueBias) {
  const ResidualFixture fx;
  // At 5 kHz the midpoint rule is exact to < 1e-6 (test_preintegration.cpp).
  const auto samples = test::sample_motion(fx.motion, 0.0, 0.6, 2e-4, fx.true_bias);
  const Preintegration pre(samples, fx.t_i, fx.t_j, fx.true_bias, kEurocAdis16448Noise);
  const ImuCost cost(pre);
  const ImuStates truth = true_states(fx.motion, fx.t_i, fx.t_j, fx.true_bias);
  const Vector9d white = evaluate(cost, truth);
  // Undo the whitening: L' L = covariance^-1, L lower triangular.
  const Vector9d raw = cost.sqrt_information().triangularView<Eigen::Lower>().solve(white);
  std::printf("residual at the truth: raw %.2e, whitened %.2e\n", raw.cwiseAbs().maxCoeff(),
              white.norm());
  EXPECT_LT(raw.cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(white.norm(), 0.05);

  // Linearised at a bias off by (0.002 rad/s, 0.02 m/s^2): the first-order correction brings the
  // residual at the true bias back to ~zero (its second-order remainder, ~1e-6), where the
  // residual at the linearisation bias itself is ~1e-3.
  ImuBias off = fx.true_bias;
  off.gyro += Eigen::Vector3d(0.002, -0.001, 0.001);
  off.acc += Eigen::Vector3d(-0.02, 0.01, 0.015);
  const ImuCost off_cost(Preintegration(samples, fx.t_i, fx.t_j, off, kEurocAdis16448Noise));
  const Vector9d off_raw =
      off_cost.sqrt_information().triangularView<Eigen::Lower>().solve(evaluate(off_cost, truth));
  EXPECT_LT(off_raw.cwiseAbs().maxCoeff(), 1e-5);
  ImuStates at_off = truth;
  const Vector6d off_vector = off.vector();
  std::copy(off_vector.data(), off_vector.data() + 6, at_off.bias_i.begin());
  const Vector9d uncorrected =
      off_cost.sqrt_information().triangularView<Eigen::Lower>().solve(evaluate(off_cost, at_off));
  EXPECT_GT(uncorrected.cwiseAbs().maxCoeff(), 1e-3);
  std::printf("linearised off the true bias: corrected %.2e, uncorrected %.2e\n",
              off_raw.cwiseAbs().maxCoeff(), uncorrected.cwiseAbs().maxCoeff());

  // And it does see a state that is wrong: pose_j 1 cm off shows as r_p = 1 cm.
  Eigen::VectorXd shift = Eigen::VectorXd::Zero(6);
  shift(1) = 0.01;
  const Vector9d shifted = cost.sqrt_information().triangularView<Eigen::Lower>().solve(
      evaluate(cost, moved(truth, 3, shift)));
  EXPECT_NEAR(shifted.tail<3>().norm(), 0.01, 1e-6);
  EXPECT_LT(shifted.head<6>().cwiseAbs().maxCoeff(), 1e-6);
}

TEST(ImuCost, JacobiansMatchNumericDifferentiationOnTheManifold) {
  const ResidualFixture fx;
  const auto samples = test::sample_motion(fx.motion, 0.0, 0.6, 0.005, fx.true_bias);
  const ImuBias linearisation{fx.true_bias.gyro + Eigen::Vector3d(0.004, 0.0, -0.003),
                              fx.true_bias.acc + Eigen::Vector3d(0.0, 0.05, -0.03)};
  const ImuCost cost(Preintegration(samples, fx.t_i, fx.t_j, linearisation, kEurocAdis16448Noise));
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto random = [&](int size, double scale) -> Eigen::VectorXd {
    Eigen::VectorXd d(size);
    for (int c = 0; c < size; ++c) d(c) = scale * n(rng);
    return d;
  };
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    // The true states moved well off: 0.3 m, 0.3 rad, 0.3 m/s, and the bias off the linearisation.
    ImuStates x = true_states(fx.motion, fx.t_i, fx.t_j, fx.true_bias);
    x = moved(x, 0, random(6, 0.3));
    x = moved(x, 1, random(3, 0.3));
    x = moved(x, 2, (Eigen::VectorXd(6) << random(3, 0.01), random(3, 0.1)).finished());
    x = moved(x, 3, random(6, 0.3));
    x = moved(x, 4, random(3, 0.3));
    std::array<Eigen::Matrix<double, 9, Eigen::Dynamic, Eigen::RowMajor>, 5> J;
    std::array<double*, 5> jac{};
    for (size_t k = 0; k < 5; ++k) {
      J[k].resize(9, kBlockSizes[k]);
      J[k].setConstant(std::nan(""));
      jac[k] = J[k].data();
    }
    Vector9d r;
    const auto blocks = x.blocks();
    ASSERT_TRUE(cost.Evaluate(blocks.data(), r.data(), jac.data()));
    EXPECT_GT(r.norm(), 1.0) << "the residual must not vanish here";
    EXPECT_LT((r - evaluate(cost, x)).norm(), 1e-12);
    for (int k = 0; k < 5; ++k) {
      const size_t ku = static_cast<size_t>(k);
      const auto f = [&](const Eigen::VectorXd& d) {
        return Eigen::VectorXd(evaluate(cost, moved(x, k, d)));
      };
      const Eigen::MatrixXd numeric = test::central_differences(f, kTangentSizes[ku], 1e-6);
      const Eigen::MatrixXd analytic = J[ku].leftCols(kTangentSizes[ku]);
      const double e = test::relative_error(analytic, numeric);
      worst = std::max(worst, e);
      EXPECT_LT(e, 1e-6) << "block " << k << ", trial " << trial << "\n"
                         << analytic << "\n\n"
                         << numeric;
      if (kBlockSizes[ku] == 7) {
        EXPECT_EQ(J[ku].col(6).norm(), 0.0) << "block " << k;
      }
    }
  }
  std::printf("IMU residual Jacobians: worst relative error %.2e\n", worst);
}

TEST(ImuCost, RejectsADegenerateCovariance) {
  const ResidualFixture fx;
  const auto samples = test::sample_motion(fx.motion, 0.0, 0.6, 0.005);
  EXPECT_THROW(ImuCost(Preintegration(samples, fx.t_i, fx.t_j, {}, ImuNoise{})),
               std::invalid_argument);
  // One step: velocity and position errors come from the same noise, fully correlated.
  EXPECT_THROW(ImuCost(Preintegration(samples, 0.2001, 0.2042, {}, kEurocAdis16448Noise)),
               std::invalid_argument);
  EXPECT_NO_THROW(ImuCost(Preintegration(samples, 0.2001, 0.2142, {}, kEurocAdis16448Noise)));
}

TEST(BiasRandomWalkCost, WhitenedByTheWalkOverTheIntervalWithExactJacobians) {
  const ResidualFixture fx;
  const auto samples = test::sample_motion(fx.motion, 0.0, 0.6, 0.005);
  const ImuNoise noise = kEurocAdis16448Noise;
  const Preintegration pre(samples, fx.t_i, fx.t_j, {}, noise);
  const BiasRandomWalkCost cost(pre);
  const double dt = fx.t_j - fx.t_i;
  std::array<double, 6> bi = {0.01, -0.02, 0.03, 0.1, 0.2, -0.3};
  std::array<double, 6> bj = {0.012, -0.021, 0.027, 0.13, 0.18, -0.31};
  const double* params[] = {bi.data(), bj.data()};
  Vector6d r;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> Ji, Jj;
  double* jac[] = {Ji.data(), Jj.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jac));
  for (int c = 0; c < 6; ++c) {
    const double sigma = (c < 3 ? noise.gyro_random_walk : noise.acc_random_walk) * std::sqrt(dt);
    EXPECT_NEAR(r(c), (bj[static_cast<size_t>(c)] - bi[static_cast<size_t>(c)]) / sigma,
                1e-9 * std::abs(r(c)));
  }
  for (int k = 0; k < 2; ++k) {
    const auto f = [&](const Eigen::VectorXd& d) {
      std::array<double, 6> a = bi, b = bj;
      for (size_t c = 0; c < 6; ++c) (k == 0 ? a : b)[c] += d(static_cast<Eigen::Index>(c));
      const double* p[] = {a.data(), b.data()};
      Vector6d out;
      cost.Evaluate(p, out.data(), nullptr);
      return Eigen::VectorXd(out);
    };
    const Eigen::MatrixXd numeric = test::central_differences(f, 6, 1e-6);
    EXPECT_LT(test::relative_error(k == 0 ? Ji : Jj, numeric), 1e-6) << "block " << k;
  }
  ImuNoise no_walk = noise;
  no_walk.acc_random_walk = 0.0;
  EXPECT_THROW(BiasRandomWalkCost(Preintegration(samples, fx.t_i, fx.t_j, {}, no_walk)),
               std::invalid_argument);
}

TEST(ImuPoseManifold, PlusIsTheBodyFrameRetractionAndMinusItsInverse) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  const ImuPoseManifold manifold;
  for (int trial = 0; trial < 50; ++trial) {
    Vector6d xi, delta;
    for (int c = 0; c < 6; ++c) {
      xi(c) = 2.0 * n(rng);
      delta(c) = 0.5 * n(rng);
    }
    const SE3 T = SE3::exp(xi);
    const ImuPoseParams x = imu_pose_params(T);
    ImuPoseParams y{};
    ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
    const SE3 Ty = imu_pose_from_params(y.data());
    const Eigen::Matrix3d R_expected =
        T.rotation() *
        Eigen::AngleAxisd(delta.tail<3>().norm(), delta.tail<3>().normalized()).toRotationMatrix();
    EXPECT_LT((Ty.rotation() - R_expected).norm(), 1e-12);
    EXPECT_LT((Ty.translation() - (T.translation() + T.rotation() * delta.head<3>())).norm(),
              1e-12);
    EXPECT_NEAR(Eigen::Map<const Eigen::Vector4d>(y.data() + 3).norm(), 1.0, 1e-14);
    Vector6d back;
    ASSERT_TRUE(manifold.Minus(y.data(), x.data(), back.data()));
    EXPECT_LT((back - delta).norm(), 1e-12);
  }
}

// Ceres, through ImuPoseManifold, moves state j to where the IMU says it is, from state i.
TEST(ImuCost, CeresRecoversStateJFromStateIThroughTheManifold) {
  const ResidualFixture fx;
  const auto samples = test::sample_motion(fx.motion, 0.0, 0.6, 2e-4, fx.true_bias);
  const Preintegration pre(samples, fx.t_i, fx.t_j, fx.true_bias, kEurocAdis16448Noise);
  const ImuStates truth = true_states(fx.motion, fx.t_i, fx.t_j, fx.true_bias);
  ImuStates x = moved(truth, 3, (Eigen::VectorXd(6) << 0.3, -0.2, 0.1, 0.2, -0.3, 0.25).finished());
  x = moved(x, 4, Eigen::Vector3d(0.5, -0.4, 0.3));

  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  ImuPoseManifold manifold;
  auto blocks = x.blocks();
  problem.AddResidualBlock(new ImuCost(pre), nullptr, blocks[0], blocks[1], blocks[2], blocks[3],
                           blocks[4]);
  problem.SetManifold(blocks[0], &manifold);
  problem.SetManifold(blocks[3], &manifold);
  for (const size_t fixed : {0u, 1u, 2u}) problem.SetParameterBlockConstant(blocks[fixed]);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 20;
  solver.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  const SE3 Tj = imu_pose_from_params(x.pose_j.data());
  const SE3 Tj_true = imu_pose_from_params(truth.pose_j.data());
  EXPECT_LT((Tj.translation() - Tj_true.translation()).norm(), 1e-6);
  EXPECT_LT(geometry::so3_log(Tj_true.rotation().transpose() * Tj.rotation()).norm(), 1e-6);
  EXPECT_LT((Eigen::Map<const Eigen::Vector3d>(x.v_j.data()) -
             Eigen::Map<const Eigen::Vector3d>(truth.v_j.data()))
                .norm(),
            1e-6);
  EXPECT_LE(summary.iterations.size(), 10u) << summary.BriefReport();
}

}  // namespace
}  // namespace plslam::inertial
