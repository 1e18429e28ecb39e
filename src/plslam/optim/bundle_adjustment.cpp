#include "plslam/optim/bundle_adjustment.h"

#include <stdexcept>
#include <string>

#include "plslam/core/error.h"
#include "plslam/optim/ba_pass.h"
#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {
namespace {

using geometry::SE3;

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
  if (p.keyframe_factors.empty()) return;
  if (p.keyframe_extra.size() != p.keyframes.size()) {
    throw InputError("", "bundle_adjust: keyframe factors need one extra state per keyframe (" +
                             std::to_string(p.keyframe_extra.size()) + " for " + std::to_string(p.keyframes.size()) +
                             " keyframes)");
  }
  for (const auto& f : p.keyframe_factors) {
    for (const int k : f->keyframes()) {
      if (bad(k, p.keyframes.size())) {
        throw InputError("", "bundle_adjust: keyframe factor index out of range (keyframe " + std::to_string(k) + ")");
      }
    }
  }
}

// Chi-square classification of every observation at state s (behind a camera = outlier).
BaExclusions gate(const geometry::StereoCamera& cam, const BaProblem& p, const BaOptions& opt,
                  const BaState& s) {
  BaExclusions g;
  g.point_out.resize(p.point_observations.size());
  g.line_out.resize(p.line_observations.size());
  Eigen::Vector3d r;
  for (std::size_t k = 0; k < p.point_observations.size(); ++k) {
    const auto& o = p.point_observations[k];
    const SE3& T = s.poses[static_cast<std::size_t>(o.keyframe)];
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
    const SE3& T = s.poses[static_cast<std::size_t>(o.keyframe)];
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

BaPassSummary run_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                       const BaOptions& opt, const BaPassSpec& spec, BaState* s) {
  if (opt.backend == BaBackend::kSchurLM) {
    int free_keyframes = 0;
    for (const auto& kf : p.keyframes) free_keyframes += kf.fixed ? 0 : 1;
    // Keyframe factors add 9 dense unknowns per keyframe: the limit is on the system's size.
    const int per_keyframe = p.keyframe_factors.empty() ? 6 : 15;
    if (per_keyframe * free_keyframes <= 6 * opt.max_dense_keyframes) return schur_lm_ba_pass(cam, p, opt, spec, s);
    BaOptions sparse = opt;
    sparse.linear_solver = BaLinearSolver::kSparseSchur;
    const BaExclusions ex = with_behind_camera(p, spec, *s);
    BaPassSpec valid = spec;
    valid.excluded = &ex;
    return ceres_ba_pass(cam, p, sparse, valid, s);
  }
  return ceres_ba_pass(cam, p, opt, spec, s);
}

}  // namespace

BaExclusions with_behind_camera(const BaProblem& p, const BaPassSpec& spec,
                                const BaState& s) {
  BaExclusions ex;
  if (spec.excluded) ex = *spec.excluded;
  ex.point_out.resize(p.point_observations.size(), false);
  ex.line_out.resize(p.line_observations.size(), false);
  for (std::size_t k = 0; k < p.point_observations.size(); ++k) {
    const auto& o = p.point_observations[k];
    const Eigen::Vector3d Xc = s.poses[static_cast<std::size_t>(o.keyframe)] * s.points[static_cast<std::size_t>(o.point)];
    if (!(Xc.z() > 0.0)) ex.point_out[k] = true;
  }
  for (std::size_t k = 0; k < p.line_observations.size(); ++k) {
    const auto& o = p.line_observations[k];
    const auto& T = s.poses[static_cast<std::size_t>(o.keyframe)];
    const auto& L = s.lines[static_cast<std::size_t>(o.line)];
    if (!((T * Eigen::Vector3d(L.head<3>())).z() > 0.0) || !((T * Eigen::Vector3d(L.tail<3>())).z() > 0.0)) ex.line_out[k] = true;
  }
  return ex;
}

BaResult bundle_adjust(const geometry::StereoCamera& cam, const BaProblem& p,
                       const BaOptions& opt) {
  check_indices(p);
  BaState s;
  s.poses.reserve(p.keyframes.size());
  for (const auto& kf : p.keyframes) s.poses.push_back(kf.T_cw);
  s.points.reserve(p.points.size());
  for (const auto& pt : p.points) s.points.push_back(pt.position);
  s.lines.reserve(p.lines.size());
  for (const auto& l : p.lines) {
    s.lines.emplace_back();
    s.lines.back() << l.start, l.end;
  }
  if (!p.keyframe_factors.empty()) s.extra = p.keyframe_extra;

  BaResult res;
  const auto first = run_pass(cam, p, opt, {opt.robust, opt.iterations, nullptr}, &s);
  res.initial_cost = first.initial_cost;
  res.final_cost = first.final_cost;
  res.iterations = first.iterations;
  res.usable = first.usable;
  res.message = first.message;
  const auto aborted = [&] { return opt.abort && opt.abort->load(); };
  if (opt.remove_outliers && opt.second_pass_iterations > 0 && !aborted()) {
    const BaExclusions g = gate(cam, p, opt, s);
    const auto second = run_pass(cam, p, opt, {false, opt.second_pass_iterations, &g}, &s);
    res.final_cost = second.final_cost;
    res.iterations += second.iterations;
    res.usable = res.usable && second.usable;
    res.message = second.message;
  }
  res.aborted = aborted();
  BaExclusions final_gates = gate(cam, p, opt, s);
  res.point_observation_outlier = std::move(final_gates.point_out);
  res.line_observation_outlier = std::move(final_gates.line_out);
  for (std::size_t k = 0; k < p.keyframes.size(); ++k) {
    res.poses.push_back(p.keyframes[k].fixed ? p.keyframes[k].T_cw : s.poses[k]);
  }
  if (!p.keyframe_factors.empty()) {
    for (std::size_t k = 0; k < p.keyframes.size(); ++k) {
      res.keyframe_extra.push_back(p.keyframes[k].fixed ? p.keyframe_extra[k] : s.extra[k]);
    }
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
