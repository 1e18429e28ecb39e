// IMU preintegration of one keyframe interval at 200 Hz: ~10 samples (20 Hz keyframes) and ~40
// samples (5 Hz keyframes), with bias Jacobians and covariance; and one evaluation of the IMU
// residual, with and without its Jacobians.
#include <array>

#include <benchmark/benchmark.h>

#include "../tests/inertial/imu_motion.h"
#include "plslam/inertial/imu_pose_manifold.h"
#include "plslam/inertial/imu_residual.h"
#include "plslam/inertial/preintegration.h"

namespace {

namespace inertial = plslam::inertial;
using plslam::geometry::SE3;

constexpr double kImuPeriod = 1.0 / 200.0;

// Arg: the samples strictly inside the interval, whose ends fall between samples.
void BM_Preintegrate(benchmark::State& state) {
  const inertial::test::SinusoidMotion motion;
  const auto samples = inertial::test::sample_motion(motion, 0.0, 1.0, kImuPeriod);
  const double t_i = 0.2 + 0.3 * kImuPeriod;
  const double t_j = t_i + static_cast<double>(state.range(0)) * kImuPeriod;
  for (auto _ : state) {
    const inertial::Preintegration pre(samples, t_i, t_j, inertial::ImuBias{},
                                       plslam::kEurocAdis16448Noise);
    benchmark::DoNotOptimize(pre.covariance().data());
  }
}
BENCHMARK(BM_Preintegrate)->Arg(10)->Arg(40)->Unit(benchmark::kMicrosecond);

// Arg: 1 with all five Jacobians, 0 the residual alone.
void BM_ImuResidual(benchmark::State& state) {
  const inertial::test::SinusoidMotion motion;
  const auto samples = inertial::test::sample_motion(motion, 0.0, 1.0, kImuPeriod);
  const double t_i = 0.2013, t_j = 0.4013;
  const inertial::ImuCost cost(inertial::Preintegration(samples, t_i, t_j, inertial::ImuBias{},
                                                        plslam::kEurocAdis16448Noise));
  const auto si = motion.at(t_i), sj = motion.at(t_j);
  const auto pose_i = inertial::imu_pose_params(SE3(si.R, si.p));
  const auto pose_j = inertial::imu_pose_params(SE3(sj.R, sj.p));
  const std::array<double, 6> bias = {0.01, -0.02, 0.005, 0.1, 0.05, -0.2};
  const double* params[] = {pose_i.data(), si.v.data(), bias.data(), pose_j.data(), sj.v.data()};
  std::array<double, 9> r{};
  std::array<double, 9 * 7> j0{}, j3{};
  std::array<double, 9 * 3> j1{}, j4{};
  std::array<double, 9 * 6> j2{};
  std::array<double*, 5> jacobians = {j0.data(), j1.data(), j2.data(), j3.data(), j4.data()};
  double** jac = state.range(0) != 0 ? jacobians.data() : nullptr;
  for (auto _ : state) {
    cost.Evaluate(params, r.data(), jac);
    benchmark::DoNotOptimize(r.data());
    benchmark::DoNotOptimize(j2.data());
  }
}
BENCHMARK(BM_ImuResidual)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

}  // namespace
