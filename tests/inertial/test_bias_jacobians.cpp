// The preintegration's bias Jacobians against central differences of re-integration, and the
// first-order bias correction against re-integration: its error must shrink with the square of
// the bias change.
#include <cstdio>

#include <gtest/gtest.h>

#include "inertial/imu_motion.h"
#include "inertial/numeric_jacobian.h"
#include "plslam/geometry/se3.h"
#include "plslam/inertial/preintegration.h"

namespace plslam::inertial {
namespace {

// 0.4 s of the closed-form motion at 200 Hz, readings offset by a bias, ends between samples.
struct BiasFixture {
  test::SinusoidMotion motion;
  ImuBias true_bias{Eigen::Vector3d(0.02, -0.01, 0.03), Eigen::Vector3d(-0.2, 0.15, 0.1)};
  std::vector<ImuSample> samples = test::sample_motion(motion, 0.0, 0.6, 0.005, true_bias);
  double t_i = 0.1037, t_j = 0.5021;
  // Linearised away from the true bias, so that the Jacobians are not taken at a special point.
  ImuBias linearisation{Eigen::Vector3d(0.01, 0.0, 0.02), Eigen::Vector3d(-0.1, 0.1, 0.0)};

  Preintegration at(const ImuBias& b) const {
    return Preintegration(samples, t_i, t_j, b, kEurocAdis16448Noise);
  }
};

ImuBias plus(const ImuBias& b, const Eigen::VectorXd& d) {
  const geometry::Vector6d v = b.vector() + d;
  return ImuBias::from_vector(v.data());
}

TEST(PreintegrationBias, JacobiansMatchCentralDifferencesOfReintegration) {
  const BiasFixture fx;
  const Preintegration pre = fx.at(fx.linearisation);
  // [dphi; dv; dp] of the deltas integrated at b + d, against those at b.
  const auto deltas_error = [&](const Eigen::VectorXd& d) {
    const Preintegration moved = fx.at(plus(fx.linearisation, d));
    Eigen::VectorXd e(9);
    e << geometry::so3_log(pre.delta_R().transpose() * moved.delta_R()),
        moved.delta_v() - pre.delta_v(), moved.delta_p() - pre.delta_p();
    return e;
  };
  const Eigen::MatrixXd numeric = test::central_differences(deltas_error, 6, 1e-5);
  const std::pair<Eigen::Matrix3d, Eigen::MatrixXd> blocks[] = {
      {pre.dR_dbg(), numeric.block(0, 0, 3, 3)},
      {pre.dv_dbg(), numeric.block(3, 0, 3, 3)},
      {pre.dv_dba(), numeric.block(3, 3, 3, 3)},
      {pre.dp_dbg(), numeric.block(6, 0, 3, 3)},
      {pre.dp_dba(), numeric.block(6, 3, 3, 3)}};
  for (const auto& [analytic, num] : blocks) {
    EXPECT_LT(test::relative_error(analytic, num), 1e-7) << analytic << "\n\n" << num;
    EXPECT_GT(analytic.norm(), 1e-3);
  }
  // The accelerometer bias cannot rotate the deltas.
  EXPECT_LT(numeric.block(0, 3, 3, 3).norm(), 1e-9);
  EXPECT_EQ(pre.bias_jacobian().block(0, 3, 3, 3).norm(), 0.0);
}

TEST(PreintegrationBias, FirstOrderCorrectionApproachesReintegrationQuadratically) {
  const BiasFixture fx;
  const Preintegration pre = fx.at(fx.linearisation);
  geometry::Vector6d direction;
  direction << 4e-3, -3e-3, 5e-3, 4e-2, 3e-2, -5e-2;
  double previous = 0.0;
  for (const double scale : {1.0, 0.5, 0.25}) {
    const ImuBias b = plus(fx.linearisation, scale * direction);
    const Preintegration exact = fx.at(b);
    const double correction_error =
        geometry::so3_log(exact.delta_R().transpose() * pre.corrected_delta_R(b)).norm() +
        (exact.delta_v() - pre.corrected_delta_v(b)).norm() +
        (exact.delta_p() - pre.corrected_delta_p(b)).norm();
    const double change = geometry::so3_log(exact.delta_R().transpose() * pre.delta_R()).norm() +
                          (exact.delta_v() - pre.delta_v()).norm() +
                          (exact.delta_p() - pre.delta_p()).norm();
    std::printf("bias change x%.2f: deltas moved %.3e, first-order correction off by %.3e\n", scale,
                change, correction_error);
    EXPECT_LT(correction_error, 2e-3 * change);
    if (previous > 0.0) {
      EXPECT_GT(previous / correction_error, 3.5);
      EXPECT_LT(previous / correction_error, 4.5);
    }
    previous = correction_error;
  }
  // At the linearisation bias itself, the correction is no correction.
  EXPECT_EQ(pre.corrected_delta_R(fx.linearisation), pre.delta_R());
  EXPECT_EQ(pre.corrected_delta_v(fx.linearisation), pre.delta_v());
  EXPECT_EQ(pre.corrected_delta_p(fx.linearisation), pre.delta_p());
}

// The default thresholds keep the correction's error small against the noise: changes of the
// bias just below both, over a 0.5 s interval, against the deltas' standard deviations.
TEST(PreintegrationBias, BelowTheReintegrationThresholdsTheCorrectionErrorIsSmallAgainstNoise) {
  const test::SinusoidMotion motion;
  const auto samples = test::sample_motion(motion, 0.0, 0.7, 0.005);
  const Preintegration pre(samples, 0.1, 0.6, ImuBias{}, kEurocAdis16448Noise);
  const ReintegrationThresholds thresholds;
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, -1.0, 1.0).normalized();
  const ImuBias b{0.999 * thresholds.gyro * direction, 0.999 * thresholds.acc * direction};
  ASSERT_FALSE(pre.bias_moved_far(b));
  const Preintegration exact(samples, 0.1, 0.6, b, kEurocAdis16448Noise);
  const Vector9d sigma = pre.covariance().diagonal().cwiseSqrt();
  const double errors[] = {
      geometry::so3_log(exact.delta_R().transpose() * pre.corrected_delta_R(b)).norm() / sigma(0),
      (exact.delta_v() - pre.corrected_delta_v(b)).norm() / sigma(3),
      (exact.delta_p() - pre.corrected_delta_p(b)).norm() / sigma(6)};
  std::printf("at the thresholds over 0.5 s: correction off by %.3f %.3f %.3f sigma (R v p)\n",
              errors[0], errors[1], errors[2]);
  for (const double e : errors) EXPECT_LT(e, 0.05);
}

}  // namespace
}  // namespace plslam::inertial
