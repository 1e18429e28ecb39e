// IMU preintegration of one keyframe interval at 200 Hz: ~10 samples (20 Hz keyframes) and ~40
// samples (5 Hz keyframes), with bias Jacobians and covariance; and one evaluation of the IMU
// residual, with and without its Jacobians; tracking's pose optimisation of one frame with 150
// stereo points, without and with the IMU (inertial/inertial_pose.h).
#include <array>

#include <benchmark/benchmark.h>

#include "../tests/inertial/imu_motion.h"
#include "../tests/inertial/stereo_view.h"
#include "plslam/inertial/inertial_pose.h"
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

// Arg: 0 the pose-only optimisation, 1 with the IMU since the state 50 ms before (20 Hz frames).
void BM_PoseOptimisation(benchmark::State& state) {
  const inertial::test::SinusoidMotion motion;
  const auto samples = inertial::test::sample_motion(motion, 0.0, 1.0, kImuPeriod);
  const double t_i = 0.4, t_j = 0.45;
  const SE3 T_imu_cam((Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished(), Eigen::Vector3d(0.06, -0.01, 0.02));
  const plslam::geometry::StereoCamera cam(450, 450, 376, 240, 0.11 * 450, 752, 480);
  const auto si = motion.at(t_i), sj = motion.at(t_j);
  const inertial::InertialState i{SE3(si.R, si.p), si.v, {}};
  const SE3 T_cw = (SE3(sj.R, sj.p) * T_imu_cam).inverse();
  const auto points = inertial::test::stereo_points_in_view(cam, T_cw, 150, 0.5);
  const SE3 guess = SE3::exp((plslam::geometry::Vector6d() << 0.01, -0.005, 0.008, 0.005, 0.003, -0.004).finished()) * T_cw;
  const inertial::InertialTerms terms(
      inertial::Preintegration(samples, t_i, t_j, inertial::ImuBias{}, plslam::kEurocAdis16448Noise), i, T_imu_cam);
  for (auto _ : state) {
    if (state.range(0) == 0) {
      benchmark::DoNotOptimize(plslam::optim::optimize_pose(cam, guess, points, {}).T_cw);
    } else {
      benchmark::DoNotOptimize(inertial::optimize_pose_inertial(cam, terms, guess, sj.v, {}, points, {}).state.v);
    }
  }
}
BENCHMARK(BM_PoseOptimisation)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
