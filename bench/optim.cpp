// Optimiser timings: pose-only (1000 points + 200 lines), local BA (10 keyframes, 5000 points,
// 500 lines, 10 LM iterations; hand-written Schur LM against Ceres in the same run), and analytic
// vs autodiff evaluation of the Ceres costs.
#include <random>

#include <benchmark/benchmark.h>
#include <ceres/autodiff_cost_function.h>

#include "../tests/optim/synthetic_scene.h"
#include "plslam/optim/bundle_adjustment.h"
#include "plslam/optim/ceres_costs.h"
#include "plslam/optim/pose_only.h"

namespace {

using plslam::geometry::SE3;
namespace optim = plslam::optim;
namespace test = plslam::test;

void BM_PoseOnly(benchmark::State& state) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(1);
  const SE3 T_true = test::random_pose(rng, 5.0, 1.0);
  const auto scene = test::make_pose_only_scene(cam, T_true, static_cast<int>(state.range(0)),
                                                static_cast<int>(state.range(1)), 1.0, 0.2, rng);
  const SE3 T_init = test::random_pose(rng, 0.1, 0.03) * T_true;
  double err = 0.0;
  int iterations = 0;
  for (auto _ : state) {
    const auto res = optim::optimize_pose(cam, T_init, scene.points, scene.lines);
    benchmark::DoNotOptimize(res.T_cw);
    err = test::centre_error(res.T_cw, T_true);
    iterations = res.iterations;
  }
  state.counters["err_mm"] = err * 1e3;
  state.counters["lm_iters"] = iterations;
}
BENCHMARK(BM_PoseOnly)->Args({1000, 200})->Args({1000, 0})->Args({0, 200})
    ->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

// Local BA at the size. Args: {backend: 0 Schur LM, 1 Ceres DENSE_SCHUR, 2 Ceres
// SPARSE_SCHUR; second pass with outlier removal (0/1); threads; forced: 1 px observation noise
// and no function tolerance, so that exactly 10 LM iterations run (0: exact observations, the
// solvers stop when converged)}. CPU time is the whole process' (worker threads included), so
// threaded variants are not flattered; wall time is also reported but depends on the other jobs
// sharing the machine.
void BM_BundleAdjustment(benchmark::State& state) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(2);
  auto scene = test::make_ba_scene(cam, 10, 5000, 500, rng);
  scene.problem.keyframes[0].fixed = scene.problem.keyframes[1].fixed = true;
  test::perturb(&scene.problem, 0.02, 0.005, 0.02, rng);
  optim::BaOptions opt;
  opt.iterations = 10;
  if (state.range(3) != 0) {
    std::normal_distribution<double> noise(0.0, 1.0);
    for (auto& o : scene.problem.point_observations) {
      o.measurement += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    }
    for (auto& o : scene.problem.line_observations) {
      o.left_line(2) += noise(rng);
      o.right_line(2) += noise(rng);
    }
    opt.function_tolerance = 0.0;
  }
  opt.backend = state.range(0) == 0 ? optim::BaBackend::kSchurLM : optim::BaBackend::kCeres;
  opt.linear_solver = state.range(0) == 2 ? optim::BaLinearSolver::kSparseSchur
                                          : optim::BaLinearSolver::kDenseSchur;
  opt.remove_outliers = state.range(1) != 0;
  opt.num_threads = static_cast<int>(state.range(2));
  double err = 0.0;
  int iterations = 0;
  for (auto _ : state) {
    const auto res = optim::bundle_adjust(cam, scene.problem, opt);
    benchmark::DoNotOptimize(res.poses);
    err = 0.0;
    for (std::size_t k = 0; k < res.poses.size(); ++k) {
      err = std::max(err, test::centre_error(res.poses[k], scene.poses_true[k]));
    }
    iterations = res.iterations;
  }
  state.counters["point_obs"] = static_cast<double>(scene.problem.point_observations.size());
  state.counters["line_obs"] = static_cast<double>(scene.problem.line_observations.size());
  state.counters["max_pose_err_mm"] = err * 1e3;
  state.counters["lm_iters"] = iterations;  // Ceres counts its iteration 0 too
}
BENCHMARK(BM_BundleAdjustment)
    ->ArgNames({"backend", "second_pass", "threads", "forced"})
    ->Args({0, 0, 1, 0})->Args({1, 0, 1, 0})->Args({2, 0, 1, 0})
    ->Args({0, 0, 1, 1})->Args({1, 0, 1, 1})
    ->Args({0, 1, 1, 0})->Args({1, 1, 1, 0})
    ->Args({0, 0, 2, 0})->Args({1, 0, 2, 0})
    ->UseRealTime()->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

// Autodiff twins of the analytic costs, on the same 7-number pose block [t, q_xyzw].
struct PointFunctor {
  plslam::geometry::StereoCamera cam;
  Eigen::Vector3d z;
  template <typename T>
  bool operator()(const T* pose, const T* X, T* r) const {
    const Eigen::Quaternion<T> q(pose[6], pose[3], pose[4], pose[5]);
    const Eigen::Matrix<T, 3, 1> Xc =
        q * Eigen::Matrix<T, 3, 1>(X[0], X[1], X[2]) + Eigen::Matrix<T, 3, 1>(pose[0], pose[1], pose[2]);
    const T iz = T(1.0) / Xc.z();
    const T ul = cam.fx() * Xc.x() * iz + cam.cx();
    r[0] = ul - z(0);
    r[1] = cam.fy() * Xc.y() * iz + cam.cy() - z(1);
    r[2] = ul - cam.bf() * iz - z(2);
    return true;
  }
};

struct LinePairFunctor {
  plslam::geometry::StereoCamera cam;
  Eigen::Vector3d l;
  bool right;
  template <typename T>
  bool operator()(const T* pose, const T* P, T* r) const {
    const Eigen::Quaternion<T> q(pose[6], pose[3], pose[4], pose[5]);
    const Eigen::Matrix<T, 3, 1> t(pose[0], pose[1], pose[2]);
    for (int k = 0; k < 2; ++k) {
      const Eigen::Matrix<T, 3, 1> Xc = q * Eigen::Matrix<T, 3, 1>(P[3 * k], P[3 * k + 1], P[3 * k + 2]) + t;
      const T iz = T(1.0) / Xc.z();
      T u = cam.fx() * Xc.x() * iz + cam.cx();
      if (right) u -= cam.bf() * iz;
      r[k] = l(0) * u + l(1) * (cam.fy() * Xc.y() * iz + cam.cy()) + l(2);
    }
    return true;
  }
};

template <int Kind>  // 0 analytic point, 1 autodiff point, 2 analytic line, 3 autodiff line
void BM_CostEvaluation(benchmark::State& state) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(3);
  const SE3 T = test::random_pose(rng, 5.0, 1.0);
  const optim::PoseParams x = optim::to_params(T);
  const Eigen::Vector3d X = test::world_point_at(cam, T, test::random_pixel(cam, rng), 10.0);
  const auto [Ps, Pe] = test::random_segment(cam, T, rng);
  Eigen::Matrix<double, 6, 1> ends;
  ends << Ps, Pe;
  const auto po = test::observe_point(cam, T, X, 1.0, rng);
  const auto lo = test::observe_line(cam, T, Ps, Pe, 1.0, rng);
  std::unique_ptr<ceres::CostFunction> cost;
  if constexpr (Kind == 0) cost = std::make_unique<optim::StereoPointCost>(cam, po, 1.0);
  if constexpr (Kind == 1) {
    cost.reset(new ceres::AutoDiffCostFunction<PointFunctor, 3, 7, 3>(new PointFunctor{cam, po.measurement}));
  }
  if constexpr (Kind == 2) cost = std::make_unique<optim::StereoLinePairCost>(cam, lo, true, 1.0);
  if constexpr (Kind == 3) {
    cost.reset(new ceres::AutoDiffCostFunction<LinePairFunctor, 2, 7, 6>(new LinePairFunctor{cam, lo.right_line, true}));
  }
  const bool is_point = Kind < 2;
  const double* params[] = {x.data(), is_point ? X.data() : ends.data()};
  double r[3], j0[3 * 7], j1[3 * 6];
  double* jacs[] = {j0, j1};
  for (auto _ : state) {
    cost->Evaluate(params, r, jacs);
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(j0);
    benchmark::DoNotOptimize(j1);
  }
}
BENCHMARK(BM_CostEvaluation<0>)->Name("BM_Cost/point_analytic")->Unit(benchmark::kNanosecond);
BENCHMARK(BM_CostEvaluation<1>)->Name("BM_Cost/point_autodiff")->Unit(benchmark::kNanosecond);
BENCHMARK(BM_CostEvaluation<2>)->Name("BM_Cost/line_pair_analytic")->Unit(benchmark::kNanosecond);
BENCHMARK(BM_CostEvaluation<3>)->Name("BM_Cost/line_pair_autodiff")->Unit(benchmark::kNanosecond);

}  // namespace
