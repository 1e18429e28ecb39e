// Evaluation speed on long trajectories: 100k poses, association + se3 alignment + APE + RPE,
// plus the KITTI metric and RPE over all pairs in metres.
#include <benchmark/benchmark.h>

#include <cmath>

#include <Eigen/Geometry>

#include "plslam/eval/evaluate.h"

namespace {

plslam::Trajectory make_trajectory(int n, double time_offset, double wobble) {
  plslam::Trajectory traj;
  traj.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double a = 1e-3 * i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(a + wobble * std::sin(0.1 * i), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(200 * std::cos(a), 150 * std::sin(a), 0.001 * i) +
                      wobble * Eigen::Vector3d(std::sin(0.3 * i), std::cos(0.2 * i), 0);
    traj.push_back({0.05 * i + time_offset, T});
  }
  return traj;
}

void run(benchmark::State& state, plslam::eval::EvalOptions options) {
  const int n = static_cast<int>(state.range(0));
  const auto gt = make_trajectory(n, 0.0, 0.0);
  const auto est = make_trajectory(n, 0.002, 0.05);
  for (auto _ : state) {
    auto r = plslam::eval::evaluate(gt, est, options);
    benchmark::DoNotOptimize(r.ape_trans_stats.rmse);
  }
  state.SetItemsProcessed(state.iterations() * n);
}

void BM_EvalDefault(benchmark::State& state) { run(state, {}); }

void BM_EvalSim3KittiMetric(benchmark::State& state) {
  plslam::eval::EvalOptions o;
  o.align = plslam::eval::AlignMode::kSim3;
  o.kitti_metric = true;
  run(state, o);
}

void BM_EvalRpe10mAllPairs(benchmark::State& state) {
  plslam::eval::EvalOptions o;
  o.rpe.delta = 10.0;
  o.rpe.unit = plslam::eval::DeltaUnit::kMeters;
  o.rpe.all_pairs = true;
  run(state, o);
}

BENCHMARK(BM_EvalDefault)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EvalSim3KittiMetric)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EvalRpe10mAllPairs)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
