#include "plslam/optim/bundle_adjustment.h"

#include <cmath>
#include <memory>
#include <string>

#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "plslam/core/error.h"
#include "plslam/optim/ceres_costs.h"
#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {
namespace {

using geometry::SE3;

// Mutable optimisation state: Ceres works on these arrays in place.
struct State {
  std::vector<PoseParams> poses;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix<double, 6, 1>> lines;  // [start; end]
};

void check_indices(const BaProblem& p) {
  const auto bad = [](int i, std::size_t n) { return i < 0 || static_cast<std::size_t>(i) >= n; };
  for (const auto& o : p.point_observations) {
    if (bad(o.keyframe, p.keyframes.size()) || bad(o.point, p.points.size())) {
      throw InputError("", "bundle_adjust: point observation index out of range (keyframe " +
                               std::to_string(o.keyframe) + ", point " + std::to_string(o.point) + ")");
    }
  }
  for (const auto& o : p.line_observations) {
    if (bad(o.keyframe, p.keyframes.size()) || bad(o.line, p.lines.size())) {
      throw InputError("", "bundle_adjust: line observation index out of range (keyframe " +
                               std::to_string(o.keyframe) + ", line " + std::to_string(o.line) + ")");
    }
  }
}

struct Gates {
  std::vector<bool> point_out, line_out;
};

Gates gate(const geometry::StereoCamera& cam, const BaProblem& p, const BaOptions& opt,
           const State& s) {
  Gates g;
  g.point_out.resize(p.point_observations.size());
  g.line_out.resize(p.line_observations.size());
  Eigen::Vector3d r;
  for (std::size_t k = 0; k < p.point_observations.size(); ++k) {
    const auto& o = p.point_observations[k];
    const SE3 T = from_params(s.poses[static_cast<std::size_t>(o.keyframe)].data());
    bool out = true;
    if (evaluate_stereo_point(cam, T, s.points[static_cast<std::size_t>(o.point)], o.measurement,
                              o.has_right, &r, nullptr, nullptr)) {
      const double chi2 = level_information(o.level, opt.scale_factor) * r.squaredNorm();
      out = chi2 > (o.has_right ? opt.chi2_point_stereo : opt.chi2_point_mono);
    }
    g.point_out[k] = out;
  }
  Eigen::Vector4d rl;
  for (std::size_t k = 0; k < p.line_observations.size(); ++k) {
    const auto& o = p.line_observations[k];
    const SE3 T = from_params(s.poses[static_cast<std::size_t>(o.keyframe)].data());
    const auto li = static_cast<std::size_t>(o.line);
    bool out = true;
    const Eigen::Vector3d Ps = s.lines[li].head<3>(), Pe = s.lines[li].tail<3>();
    if (evaluate_stereo_line(cam, T, Ps, Pe, o, &rl, nullptr, nullptr, nullptr)) {
      const double info = o.information * level_information(o.level, opt.scale_factor);
      out = info * rl.head<2>().squaredNorm() > opt.chi2_line_pair ||
            info * rl.tail<2>().squaredNorm() > opt.chi2_line_pair;
    }
    g.line_out[k] = out;
  }
  return g;
}

// Builds and solves one Ceres problem over the observations not excluded; returns the summary.
ceres::Solver::Summary solve_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                                  const BaOptions& opt, bool robust, int iterations,
                                  const Gates* excluded, State* s) {
  SE3LeftManifold manifold;
  ceres::HuberLoss point_loss(std::sqrt(opt.chi2_point_stereo));
  ceres::HuberLoss mono_loss(std::sqrt(opt.chi2_point_mono));
  ceres::HuberLoss line_loss(std::sqrt(opt.chi2_line_pair));
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.disable_all_safety_checks = true;  // indices are validated up front; saves setup time
  ceres::Problem problem(po);
  auto* ordering = new ceres::ParameterBlockOrdering;  // owned by the solver options below

  std::vector<bool> pose_added(p.keyframes.size(), false);
  auto add_pose = [&](int kf) {
    const auto k = static_cast<std::size_t>(kf);
    double* x = s->poses[k].data();
    if (!pose_added[k]) {
      pose_added[k] = true;
      problem.AddParameterBlock(x, 7, &manifold);
      if (p.keyframes[k].fixed) problem.SetParameterBlockConstant(x);
      ordering->AddElementToGroup(x, 1);
    }
    return x;
  };
  std::vector<bool> point_added(p.points.size(), false);
  auto add_landmark = [&](double* x, int size, bool fixed, std::vector<bool>& added,
                          std::size_t k) {
    if (!added[k]) {
      added[k] = true;
      problem.AddParameterBlock(x, size);
      if (fixed) problem.SetParameterBlockConstant(x);
      ordering->AddElementToGroup(x, 0);
    }
  };
  for (std::size_t k = 0; k < p.point_observations.size(); ++k) {
    if (excluded && excluded->point_out[k]) continue;
    const auto& o = p.point_observations[k];
    const auto pi = static_cast<std::size_t>(o.point);
    double* pose = add_pose(o.keyframe);
    add_landmark(s->points[pi].data(), 3, p.points[pi].fixed, point_added, pi);
    const double sqrt_info = std::sqrt(level_information(o.level, opt.scale_factor));
    ceres::LossFunction* loss = robust ? (o.has_right ? &point_loss : &mono_loss) : nullptr;
    problem.AddResidualBlock(new StereoPointCost(cam, o, sqrt_info), loss, pose,
                             s->points[pi].data());
  }
  std::vector<bool> line_added(p.lines.size(), false);
  for (std::size_t k = 0; k < p.line_observations.size(); ++k) {
    if (excluded && excluded->line_out[k]) continue;
    const auto& o = p.line_observations[k];
    const auto li = static_cast<std::size_t>(o.line);
    double* pose = add_pose(o.keyframe);
    add_landmark(s->lines[li].data(), 6, p.lines[li].fixed, line_added, li);
    const double sqrt_info =
        std::sqrt(o.information * level_information(o.level, opt.scale_factor));
    ceres::LossFunction* loss = robust ? &line_loss : nullptr;
    for (const bool right : {false, true}) {
      problem.AddResidualBlock(new StereoLinePairCost(cam, o, right, sqrt_info), loss, pose,
                               s->lines[li].data());
    }
  }

  ceres::Solver::Options so;
  so.linear_solver_type = opt.linear_solver == BaLinearSolver::kDenseSchur ? ceres::DENSE_SCHUR
                                                                            : ceres::SPARSE_SCHUR;
  so.linear_solver_ordering.reset(ordering);
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.max_num_iterations = iterations;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  if (problem.NumResidualBlocks() == 0) return summary;
  ceres::Solve(so, &problem, &summary);
  return summary;
}

}  // namespace

BaResult bundle_adjust(const geometry::StereoCamera& cam, const BaProblem& p,
                       const BaOptions& opt) {
  check_indices(p);
  State s;
  s.poses.reserve(p.keyframes.size());
  for (const auto& kf : p.keyframes) s.poses.push_back(to_params(kf.T_cw));
  for (const auto& pt : p.points) s.points.push_back(pt.position);
  for (const auto& l : p.lines) {
    s.lines.emplace_back();
    s.lines.back() << l.start, l.end;
  }

  BaResult res;
  const auto first = solve_pass(cam, p, opt, opt.robust, opt.iterations, nullptr, &s);
  res.initial_cost = first.initial_cost;
  res.final_cost = first.final_cost;
  res.iterations = static_cast<int>(first.iterations.size());
  res.usable = first.IsSolutionUsable();
  res.message = first.BriefReport() + " " + first.message;
  if (opt.remove_outliers && opt.second_pass_iterations > 0) {
    const Gates g = gate(cam, p, opt, s);
    const auto second = solve_pass(cam, p, opt, false, opt.second_pass_iterations, &g, &s);
    res.final_cost = second.final_cost;
    res.iterations += static_cast<int>(second.iterations.size());
    res.usable = res.usable && second.IsSolutionUsable();
    res.message = second.BriefReport() + " " + second.message;
  }
  Gates final_gates = gate(cam, p, opt, s);
  res.point_observation_outlier = std::move(final_gates.point_out);
  res.line_observation_outlier = std::move(final_gates.line_out);
  for (std::size_t k = 0; k < p.keyframes.size(); ++k) {
    res.poses.push_back(p.keyframes[k].fixed ? p.keyframes[k].T_cw : from_params(s.poses[k].data()));
  }
  res.points = std::move(s.points);
  for (const auto& l : s.lines) res.lines.push_back({l.head<3>(), l.tail<3>()});
  return res;
}

BaResult local_bundle_adjustment(const geometry::StereoCamera& cam, const BaProblem& problem,
                                 BaOptions options) {
  options.remove_outliers = true;
  bool any_fixed = false;
  for (const auto& kf : problem.keyframes) any_fixed = any_fixed || kf.fixed;
  if (any_fixed || problem.keyframes.empty()) return bundle_adjust(cam, problem, options);
  BaProblem anchored = problem;
  anchored.keyframes.front().fixed = true;
  return bundle_adjust(cam, anchored, options);
}

BaResult global_bundle_adjustment(const geometry::StereoCamera& cam, const BaProblem& problem,
                                  const BaOptions& options) {
  BaProblem all = problem;
  for (std::size_t k = 0; k < all.keyframes.size(); ++k) all.keyframes[k].fixed = (k == 0);
  return bundle_adjust(cam, all, options);
}

}  // namespace plslam::optim
