// The Ceres backend of bundle_adjust: analytic costs of ceres_costs.h, landmarks in elimination
// group 0 so DENSE_SCHUR / SPARSE_SCHUR eliminate them first.
#include <cmath>
#include <memory>

#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "plslam/optim/ba_pass.h"
#include "plslam/optim/ceres_costs.h"

namespace plslam::optim {

BaPassSummary ceres_ba_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                            const BaOptions& opt, const BaPassSpec& spec, BaState* s) {
  // Ceres works on 7-number pose blocks in place.
  std::vector<PoseParams> poses;
  poses.reserve(s->poses.size());
  for (const auto& T : s->poses) poses.push_back(to_params(T));

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
    double* x = poses[k].data();
    if (!pose_added[k]) {
      pose_added[k] = true;
      problem.AddParameterBlock(x, 7, &manifold);
      if (p.keyframes[k].fixed) problem.SetParameterBlockConstant(x);
      ordering->AddElementToGroup(x, 1);
    }
    return x;
  };
  auto add_landmark = [&](double* x, int size, bool fixed, std::vector<bool>& added,
                          std::size_t k) {
    if (!added[k]) {
      added[k] = true;
      problem.AddParameterBlock(x, size);
      if (fixed) problem.SetParameterBlockConstant(x);
      ordering->AddElementToGroup(x, 0);
    }
  };
  const BaExclusions* excluded = spec.excluded;
  std::vector<bool> point_added(p.points.size(), false);
  for (std::size_t k = 0; k < p.point_observations.size(); ++k) {
    if (excluded && excluded->point_out[k]) continue;
    const auto& o = p.point_observations[k];
    const auto pi = static_cast<std::size_t>(o.point);
    double* pose = add_pose(o.keyframe);
    add_landmark(s->points[pi].data(), 3, p.points[pi].fixed, point_added, pi);
    const double sqrt_info = std::sqrt(level_information(o.level, opt.scale_factor));
    ceres::LossFunction* loss = spec.robust ? (o.has_right ? &point_loss : &mono_loss) : nullptr;
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
    ceres::LossFunction* loss = spec.robust ? &line_loss : nullptr;
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
  so.max_num_iterations = spec.iterations;
  so.function_tolerance = opt.function_tolerance;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  BaPassSummary out;
  if (problem.NumResidualBlocks() == 0) {
    out.message = "no observations";  // not usable: nothing was optimised
    return out;
  }
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (pose_added[k] && !p.keyframes[k].fixed) s->poses[k] = from_params(poses[k].data());
  }
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.usable = summary.IsSolutionUsable();
  out.message = summary.BriefReport() + " " + summary.message;
  return out;
}

}  // namespace plslam::optim
