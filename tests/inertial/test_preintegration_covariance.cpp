// Covariance propagation: one midpoint step's transition matrices against numeric
// differentiation, and the propagated covariance against the scatter of preintegrations of noisy
// samples.
#include <cstdio>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "inertial/imu_motion.h"
#include "inertial/numeric_jacobian.h"
#include "plslam/geometry/se3.h"
#include "plslam/inertial/midpoint_step.h"
#include "plslam/inertial/preintegration.h"

namespace plslam::inertial {
namespace {

// [dphi; dv; dp] of b against a, in the error-state convention of midpoint_step.h.
Eigen::VectorXd deltas_difference(const PreintegratedDeltas& a, const PreintegratedDeltas& b) {
  Eigen::VectorXd e(9);
  e << geometry::so3_log(a.R.transpose() * b.R), b.v - a.v, b.p - a.p;
  return e;
}

TEST(MidpointStep, TransitionMatricesMatchNumericDifferentiation) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto random3 = [&](double scale) -> Eigen::Vector3d {
    return Eigen::Vector3d(n(rng), n(rng), n(rng)) * scale;
  };
  for (int trial = 0; trial < 20; ++trial) {
    PreintegratedDeltas d;
    d.R = geometry::so3_exp(random3(1.0));
    d.v = random3(2.0);
    d.p = random3(1.0);
    const Eigen::Vector3d gyro = random3(2.0);
    const Eigen::Vector3d acc = random3(8.0);
    const double dt = 0.01 + 0.04 * trial / 20.0;
    StepTransition analytic;
    const PreintegratedDeltas next = midpoint_step(d, gyro, acc, dt, &analytic);

    const auto from_state = [&](const Eigen::VectorXd& e) {
      PreintegratedDeltas moved = d;
      moved.R = d.R * geometry::so3_exp(e.head<3>());
      moved.v += e.segment<3>(3);
      moved.p += e.tail<3>();
      return deltas_difference(next, midpoint_step(moved, gyro, acc, dt));
    };
    const auto from_noise = [&](const Eigen::VectorXd& noise) {
      return deltas_difference(next,
                               midpoint_step(d, gyro + noise.head<3>(), acc + noise.tail<3>(), dt));
    };
    // The structured product the propagation uses is the dense one.
    const Matrix96d M = Matrix96d::Random();
    EXPECT_LT((analytic.A_times(M) - analytic.A * M).norm(), 1e-14 * (analytic.A * M).norm());
    const Eigen::MatrixXd A = test::central_differences(from_state, 9, 1e-6);
    const Eigen::MatrixXd B = test::central_differences(from_noise, 6, 1e-6);
    EXPECT_LT(test::relative_error(analytic.A, A), 1e-7) << "A, trial " << trial;
    EXPECT_LT(test::relative_error(analytic.B, B), 1e-7) << "B, trial " << trial;
    // Block by block too, so that the small blocks (dt^2, dt^3) are checked, not drowned; the
    // floor is the differences' rounding (1e-16 / h).
    for (int r = 0; r < 9; r += 3) {
      for (int c = 0; c < 9; c += 3) {
        const Eigen::Matrix3d a = analytic.A.block<3, 3>(r, c);
        EXPECT_LT((a - A.block(r, c, 3, 3)).norm(), 1e-7 * a.norm() + 1e-9)
            << "trial " << trial << ", block " << r << "," << c;
        if (c < 6) {
          const Eigen::Matrix3d b = analytic.B.block<3, 3>(r, c);
          EXPECT_LT((b - B.block(r, c, 3, 3)).norm(), 1e-7 * b.norm() + 1e-9)
              << "trial " << trial << ", block " << r << "," << c;
        }
      }
    }
  }
}

// The Monte Carlo set-up: 0.2 s (40 steps at 200 Hz, a 5 Hz keyframe interval) with ends
// between samples; the gyro's noise is EuRoC's times 20, so that the rotation's error visibly
// spreads into velocity and position and the coupling blocks of the propagation are exercised.
struct MonteCarlo {
  test::SinusoidMotion motion;
  double dt = 0.005;
  ImuNoise noise = [] {
    ImuNoise n = kEurocAdis16448Noise;
    n.gyro_noise_density *= 20.0;
    return n;
  }();
  std::vector<ImuSample> clean = test::sample_motion(motion, 0.0, 0.3, dt);
  double t_i = 0.0512, t_j = 0.2513;
  Preintegration reference{clean, t_i, t_j, ImuBias{}, noise};
  std::mt19937 rng{2024};
  std::normal_distribution<double> unit{0.0, 1.0};

  Eigen::Vector3d white(double sigma) {
    return sigma * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
  }
  Vector9d error_of(const PreintegratedDeltas& d) const {
    Vector9d e;
    e << geometry::so3_log(reference.delta_R().transpose() * d.R), d.v - reference.delta_v(),
        d.p - reference.delta_p();
    return e;
  }
};

struct ScatterStats {
  double lowest = 0.0, highest = 0.0, mean_eigenvalue = 0.0;
  double largest_whitened_mean = 0.0;
};

// The errors' scatter whitened by the propagated covariance (the identity if they agree): its
// extreme and mean eigenvalues, and the largest whitened component of the mean error.
ScatterStats whitened_scatter(const Eigen::Matrix<double, 9, Eigen::Dynamic>& errors,
                              const Matrix9d& covariance) {
  const Vector9d mean = errors.rowwise().mean();
  const Eigen::MatrixXd centred = errors.colwise() - mean;
  const Matrix9d scatter = centred * centred.transpose() / static_cast<double>(errors.cols() - 1);
  const Eigen::LLT<Matrix9d> llt(covariance);
  const Matrix9d L = llt.matrixL().solve(Matrix9d::Identity());  // L covariance L' = I
  const Eigen::SelfAdjointEigenSolver<Matrix9d> eig(L * scatter * L.transpose());
  return {eig.eigenvalues().minCoeff(), eig.eigenvalues().maxCoeff(), eig.eigenvalues().mean(),
          (L * mean).cwiseAbs().maxCoeff()};
}

// The propagation under its own noise model: each step's mean reading carries independent noise
// of variance sigma^2 / dt, drawn here step by step. 3000 draws in 9 dimensions put the extreme
// eigenvalues of a white scatter near (1 +- sqrt(9 / 3000))^2 = 0.89 and 1.11.
TEST(PreintegrationCovariance, MatchesMonteCarloOfItsNoiseModel) {
  MonteCarlo mc;
  const std::vector<ImuSample>& s = mc.reference.samples();
  constexpr int kDraws = 3000;
  Eigen::Matrix<double, 9, Eigen::Dynamic> errors(9, kDraws);
  for (int k = 0; k < kDraws; ++k) {
    PreintegratedDeltas d;
    for (size_t j = 0; j + 1 < s.size(); ++j) {
      const double h = s[j + 1].t - s[j].t;
      const Eigen::Vector3d gyro =
          0.5 * (s[j].gyro + s[j + 1].gyro) + mc.white(mc.noise.gyro_noise_density / std::sqrt(h));
      const Eigen::Vector3d acc =
          0.5 * (s[j].acc + s[j + 1].acc) + mc.white(mc.noise.acc_noise_density / std::sqrt(h));
      d = midpoint_step(d, gyro, acc, h);
    }
    errors.col(k) = mc.error_of(d);
  }
  const ScatterStats stats = whitened_scatter(errors, mc.reference.covariance());
  std::printf(
      "Monte Carlo, per-step noise (%d draws): whitened eigenvalues %.3f .. %.3f, mean %.3f\n",
      kDraws, stats.lowest, stats.highest, stats.mean_eigenvalue);
  EXPECT_GT(stats.lowest, 0.85);
  EXPECT_LT(stats.highest, 1.15);
  EXPECT_NEAR(stats.mean_eigenvalue, 1.0, 0.03);
  // The mean error is zero to first order: within 4 standard errors in every whitened direction.
  EXPECT_LT(stats.largest_whitened_mean, 4.0 / std::sqrt(kDraws));

  // The rotation's error does spread into velocity and position (strongly correlated), so that
  // a wrong coupling would show in the eigenvalues above.
  const Matrix9d& covariance = mc.reference.covariance();
  const Vector9d inv_sd = covariance.diagonal().cwiseSqrt().cwiseInverse();
  const Matrix9d correlation = inv_sd.asDiagonal() * covariance * inv_sd.asDiagonal();
  const double coupling = correlation.block<3, 6>(0, 3).cwiseAbs().maxCoeff();
  std::printf("largest correlation of rotation with velocity or position: %.2f\n", coupling);
  EXPECT_GT(coupling, 0.5);
}

// Realistic noise, through the whole class: independent noise of variance sigma^2 / dt on each
// sample, so that consecutive steps, which average neighbouring samples, share noise. The
// per-step white model ignores that sharing and comes out slightly conservative: 20000 draws
// give whitened eigenvalues 0.93 .. 1.01 (mean 0.97) at 40 steps, 0.91 .. 1.00 at 20. With 1500
// draws (spread ~ +-16% at the extremes), the bounds below allow both.
TEST(PreintegrationCovariance, MatchesMonteCarloOfNoisySamples) {
  MonteCarlo mc;
  constexpr int kDraws = 1500;
  const double sg = mc.noise.gyro_noise_density / std::sqrt(mc.dt);
  const double sa = mc.noise.acc_noise_density / std::sqrt(mc.dt);
  Eigen::Matrix<double, 9, Eigen::Dynamic> errors(9, kDraws);
  std::vector<ImuSample> noisy = mc.clean;
  for (int k = 0; k < kDraws; ++k) {
    for (size_t s = 0; s < noisy.size(); ++s) {
      noisy[s].gyro = mc.clean[s].gyro + mc.white(sg);
      noisy[s].acc = mc.clean[s].acc + mc.white(sa);
    }
    const Preintegration pre(noisy, mc.t_i, mc.t_j, ImuBias{}, mc.noise);
    errors.col(k) = mc.error_of({pre.delta_R(), pre.delta_v(), pre.delta_p()});
  }
  const ScatterStats stats = whitened_scatter(errors, mc.reference.covariance());
  std::printf(
      "Monte Carlo, noisy samples (%d draws): whitened eigenvalues %.3f .. %.3f, mean %.3f\n",
      kDraws, stats.lowest, stats.highest, stats.mean_eigenvalue);
  EXPECT_GT(stats.lowest, 0.75);
  EXPECT_LT(stats.highest, 1.2);
  EXPECT_GT(stats.mean_eigenvalue, 0.92);
  EXPECT_LT(stats.mean_eigenvalue, 1.03);
  EXPECT_LT(stats.largest_whitened_mean, 4.0 / std::sqrt(kDraws));
}

TEST(PreintegrationCovariance, BiasRandomWalkGrowsWithTheInterval) {
  const test::SinusoidMotion motion;
  const auto samples = test::sample_motion(motion, 0.0, 1.0, 0.005);
  const ImuNoise noise = kEurocAdis16448Noise;
  const Preintegration pre(samples, 0.1, 0.85, ImuBias{}, noise);
  geometry::Vector6d expected;
  expected << Eigen::Vector3d::Constant(noise.gyro_random_walk * noise.gyro_random_walk * 0.75),
      Eigen::Vector3d::Constant(noise.acc_random_walk * noise.acc_random_walk * 0.75);
  const geometry::Matrix6d cov = pre.bias_random_walk_covariance();
  EXPECT_LT((cov.diagonal() - expected).cwiseQuotient(expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ((cov - geometry::Matrix6d(cov.diagonal().asDiagonal())).norm(), 0.0);
}

}  // namespace
}  // namespace plslam::inertial
