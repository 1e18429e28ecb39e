// The Ceres backend of bundle_adjust: analytic costs of ceres_costs.h, landmarks in elimination
// group 0 so DENSE_SCHUR / SPARSE_SCHUR eliminate them first.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "plslam/optim/ba_pass.h"
#include "plslam/optim/ceres_costs.h"

namespace plslam::optim {
namespace {

// Stops the solver after the current iteration once the caller raises the flag.
class AbortCallback : public ceres::IterationCallback {
 public:
  explicit AbortCallback(const std::atomic<bool>* flag) : flag_(flag) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return flag_ && flag_->load() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::atomic<bool>* flag_;
};

// A line's two endpoints move only across the line (2 + 2 tangent directions): along it they are
// unobservable and would slide, even collapse (see the stiffness in ba_schur_lm.cpp, which holds
// them the same way).
class LineEndpointsManifold : public ceres::Manifold {
 public:
  explicit LineEndpointsManifold(const Eigen::Vector3d& direction) {
    const Eigen::Vector3d d = direction.normalized();
    const Eigen::Vector3d helper = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    B_.col(0) = d.cross(helper).normalized();
    B_.col(1) = d.cross(B_.col(0));
  }
  int AmbientSize() const override { return 6; }
  int TangentSize() const override { return 4; }
  bool Plus(const double* x, const double* delta, double* out) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 1>> y(out);
    y = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(x);
    y.head<3>() += B_ * Eigen::Map<const Eigen::Vector2d>(delta);
    y.tail<3>() += B_ * Eigen::Map<const Eigen::Vector2d>(delta + 2);
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 4, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.block<3, 2>(0, 0) = B_;
    J.block<3, 2>(3, 2) = B_;
    return true;
  }
  bool Minus(const double* y, const double* x, double* out) const override {
    const Eigen::Map<const Eigen::Matrix<double, 6, 1>> a(y), b(x);
    Eigen::Map<Eigen::Vector4d> d(out);
    d.head<2>() = B_.transpose() * (a.head<3>() - b.head<3>());
    d.tail<2>() = B_.transpose() * (a.tail<3>() - b.tail<3>());
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 4, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.block<2, 3>(0, 0) = B_.transpose();
    J.block<2, 3>(2, 3) = B_.transpose();
    return true;
  }

 private:
  Eigen::Matrix<double, 3, 2> B_;
};

// A keyframe factor (ba_keyframe_factor.h) as a Ceres cost: per keyframe its pose block (7, the
// Jacobian over the left delta in the first 6 columns, as SE3LeftManifold expects) and its
// extra-state block (9).
class KeyframeFactorCost final : public ceres::CostFunction {
 public:
  explicit KeyframeFactorCost(const BaKeyframeFactor& factor) : factor_(factor) {
    set_num_residuals(factor.rows());
    for (std::size_t k = 0; k < factor.keyframes().size(); ++k) {
      mutable_parameter_block_sizes()->push_back(7);
      mutable_parameter_block_sizes()->push_back(9);
    }
  }
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const std::size_t n = factor_.keyframes().size();
    std::vector<geometry::SE3> T;
    std::vector<Vector9d> x;
    for (std::size_t k = 0; k < n; ++k) {
      T.push_back(from_params(params[2 * k]));
      x.emplace_back(Eigen::Map<const Vector9d>(params[2 * k + 1]));
    }
    Eigen::MatrixXd J;
    const Eigen::VectorXd r = factor_.evaluate(T, x, jacobians ? &J : nullptr);
    const int rows = factor_.rows();
    Eigen::Map<Eigen::VectorXd>(residuals, rows) = r;
    if (!jacobians) return r.allFinite();
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    for (std::size_t k = 0; k < n; ++k) {
      const auto c = static_cast<Eigen::Index>(BaKeyframeFactor::kColumnsPerKeyframe * k);
      if (jacobians[2 * k]) {
        Eigen::Map<RowMajor> Jp(jacobians[2 * k], rows, 7);
        Jp.setZero();
        Jp.leftCols(6) = J.middleCols(c, 6);
      }
      if (jacobians[2 * k + 1]) Eigen::Map<RowMajor>(jacobians[2 * k + 1], rows, 9) = J.middleCols(c + 6, 9);
    }
    return r.allFinite() && J.allFinite();
  }

 private:
  const BaKeyframeFactor& factor_;
};

}  // namespace

BaPassSummary ceres_ba_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                            const BaOptions& opt, const BaPassSpec& spec, BaState* s) {
  // Every block lives in one buffer, laid out in the problem's order: per keyframe its pose (7
  // numbers, as Ceres moves them) and its extra state (9), then the points, then the lines. Ceres
  // orders the blocks of an elimination group by their address, and so its elimination order and
  // its rounding; with the blocks in separate vectors that order followed the heap, and two runs
  // of one binary differed in the 11th digit.
  constexpr std::size_t kPose = 7, kExtra = 9, kPoint = 3, kLine = 6;
  const std::size_t n_kf = s->poses.size();
  const bool with_extra = !p.keyframe_factors.empty();
  const std::size_t per_kf = kPose + (with_extra ? kExtra : 0);
  const std::size_t points_at = n_kf * per_kf;
  const std::size_t lines_at = points_at + kPoint * s->points.size();
  std::vector<double> buffer(lines_at + kLine * s->lines.size());
  auto pose_block = [&](std::size_t k) { return buffer.data() + k * per_kf; };
  auto extra_block = [&](std::size_t k) { return buffer.data() + k * per_kf + kPose; };
  auto point_block = [&](std::size_t k) { return buffer.data() + points_at + kPoint * k; };
  auto line_block = [&](std::size_t k) { return buffer.data() + lines_at + kLine * k; };
  for (std::size_t k = 0; k < n_kf; ++k) {
    const PoseParams q = to_params(s->poses[k]);
    std::copy(q.begin(), q.end(), pose_block(k));
    if (with_extra) Eigen::Map<Vector9d>(extra_block(k)) = s->extra[k];
  }
  for (std::size_t k = 0; k < s->points.size(); ++k) Eigen::Map<Eigen::Vector3d>(point_block(k)) = s->points[k];
  for (std::size_t k = 0; k < s->lines.size(); ++k) {
    Eigen::Map<Eigen::Matrix<double, 6, 1>>(line_block(k)) = s->lines[k];
  }

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
    double* x = pose_block(k);
    if (!pose_added[k]) {
      pose_added[k] = true;
      problem.AddParameterBlock(x, 7, &manifold);
      if (p.keyframes[k].fixed) problem.SetParameterBlockConstant(x);
      ordering->AddElementToGroup(x, 1);
    }
    return x;
  };
  std::vector<std::unique_ptr<LineEndpointsManifold>> line_manifolds;
  auto add_landmark = [&](double* x, int size, bool fixed, std::vector<bool>& added,
                          std::size_t k) {
    if (!added[k]) {
      added[k] = true;
      const Eigen::Vector3d d = size == 6 ? Eigen::Vector3d(x[3] - x[0], x[4] - x[1], x[5] - x[2]) : Eigen::Vector3d::Zero();
      if (size == 6 && d.norm() > 1e-9) {
        line_manifolds.push_back(std::make_unique<LineEndpointsManifold>(d));
        problem.AddParameterBlock(x, size, line_manifolds.back().get());
      } else {
        problem.AddParameterBlock(x, size);
      }
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
    double* point = point_block(pi);
    add_landmark(point, 3, p.points[pi].fixed, point_added, pi);
    const double sqrt_info = std::sqrt(level_information(o.level, opt.scale_factor));
    ceres::LossFunction* loss = spec.robust ? (o.has_right ? &point_loss : &mono_loss) : nullptr;
    problem.AddResidualBlock(new StereoPointCost(cam, o, sqrt_info), loss, pose, point);
  }
  std::vector<bool> line_added(p.lines.size(), false);
  for (std::size_t k = 0; k < p.line_observations.size(); ++k) {
    if (excluded && excluded->line_out[k]) continue;
    const auto& o = p.line_observations[k];
    const auto li = static_cast<std::size_t>(o.line);
    double* pose = add_pose(o.keyframe);
    double* line = line_block(li);
    add_landmark(line, 6, p.lines[li].fixed, line_added, li);
    const double sqrt_info =
        std::sqrt(o.information * level_information(o.level, opt.scale_factor));
    ceres::LossFunction* loss = spec.robust ? &line_loss : nullptr;
    for (const bool right : {false, true}) {
      problem.AddResidualBlock(new StereoLinePairCost(cam, o, right, sqrt_info), loss, pose, line);
    }
  }

  // Keyframe factors: the extra states join the poses' elimination group.
  std::vector<bool> extra_added(p.keyframes.size(), false);
  for (const auto& f : p.keyframe_factors) {
    std::vector<double*> blocks;
    for (const int kf : f->keyframes()) {
      blocks.push_back(add_pose(kf));
      const auto k = static_cast<std::size_t>(kf);
      double* x = extra_block(k);
      if (!extra_added[k]) {
        extra_added[k] = true;
        problem.AddParameterBlock(x, 9);
        if (p.keyframes[k].fixed) problem.SetParameterBlockConstant(x);
        ordering->AddElementToGroup(x, 1);
      }
      blocks.push_back(x);
    }
    problem.AddResidualBlock(new KeyframeFactorCost(*f), nullptr, blocks);
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
  AbortCallback abort_callback(opt.abort);
  if (opt.abort) so.callbacks.push_back(&abort_callback);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  for (std::size_t k = 0; k < n_kf; ++k) {
    if (pose_added[k] && !p.keyframes[k].fixed) s->poses[k] = from_params(pose_block(k));
    if (extra_added[k]) s->extra[k] = Eigen::Map<const Vector9d>(extra_block(k));
  }
  for (std::size_t k = 0; k < s->points.size(); ++k) {
    if (point_added[k]) s->points[k] = Eigen::Map<const Eigen::Vector3d>(point_block(k));
  }
  for (std::size_t k = 0; k < s->lines.size(); ++k) {
    if (line_added[k]) s->lines[k] = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(line_block(k));
  }
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.usable = summary.IsSolutionUsable();
  out.message = summary.BriefReport() + " " + summary.message;
  return out;
}

}  // namespace plslam::optim
