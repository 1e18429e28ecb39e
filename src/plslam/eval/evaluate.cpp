#include "plslam/eval/evaluate.h"

#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/eval/ape.h"

namespace plslam::eval {
namespace {

constexpr std::size_t kMinPairs = 3;

Trajectory pick(const Trajectory& traj, const std::vector<std::size_t>& idx) {
  Trajectory out;
  out.reserve(idx.size());
  for (std::size_t i : idx) out.push_back(traj[i]);
  return out;
}

std::string stats_line(const char* name, const char* unit, const ErrorStatistics& s) {
  return fmt::format("{:<14} rmse {:.6f}  mean {:.6f}  median {:.6f}  std {:.6f}  min {:.6f}  "
                     "max {:.6f}  sse {:.6f}  [{}]\n",
                     name, s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse, unit);
}

// RMS distance of the positions from their centroid.
double spread(const Trajectory& traj) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : traj) mean += p.T.translation();
  mean /= static_cast<double>(traj.size());
  double sum = 0.0;
  for (const auto& p : traj) sum += (p.T.translation() - mean).squaredNorm();
  return std::sqrt(sum / static_cast<double>(traj.size()));
}

double coverage_of(const Trajectory& gt, const IndexPairs& pairs, bool by_index) {
  if (by_index) return static_cast<double>(pairs.size()) / static_cast<double>(gt.size());
  const double span = gt.back().t - gt.front().t;
  if (!(span > 0.0)) return 1.0;
  return (gt[pairs.gt.back()].t - gt[pairs.gt.front()].t) / span;
}

// Why an alignment of these paired trajectories means nothing, or empty.
std::string degenerate_alignment(const Trajectory& gt, const Trajectory& est, AlignMode mode) {
  if (mode == AlignMode::kNone) return {};
  constexpr double kMinSpreadM = 1e-6;
  if (spread(gt) < kMinSpreadM) return "the paired ground-truth positions all coincide";
  if (spread(est) < kMinSpreadM) return "the paired estimated positions all coincide (a run that never moved or never started?)";
  return {};
}

}  // namespace

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options) {
  if (gt.empty()) throw InputError("", "the ground truth trajectory is empty");
  if (est.empty()) throw InputError("", "the estimated trajectory is empty");
  EvalResult r;
  r.gt_poses = gt.size();
  r.est_poses = est.size();
  r.paired_by_index = options.pair_by_index;
  r.align = options.align;
  r.rpe_options = options.rpe;

  std::vector<double> gt_t, est_t;
  if (options.pair_by_index) {
    r.pairs = associate_by_index(gt.size(), est.size());
  } else {
    gt_t.reserve(gt.size());
    est_t.reserve(est.size());
    for (const auto& p : gt) gt_t.push_back(p.t);
    for (const auto& p : est) est_t.push_back(p.t);
    r.pairs = associate_by_time(gt_t, est_t, options.t_max_diff);
  }
  if (r.pairs.size() < kMinPairs) {
    throw InputError("", fmt::format("only {} pose pairs matched (of {} ground-truth and {} estimated "
                                     "poses{}); at least {} are needed",
                                     r.pairs.size(), gt.size(), est.size(),
                                     options.pair_by_index ? "" : fmt::format(", max time difference {} s",
                                                                              options.t_max_diff),
                                     kMinPairs));
  }
  r.coverage = coverage_of(gt, r.pairs, options.pair_by_index);
  if (r.pairs.size() < options.min_pairs || r.coverage < options.min_coverage) {
    throw InputError("", fmt::format("the estimate covers {:.0f} % of the ground truth with {} pose pairs; "
                                     "at least {:.0f} % and {} pairs are needed to score it "
                                     "(--allow-partial scores it anyway)",
                                     100.0 * r.coverage, r.pairs.size(), 100.0 * options.min_coverage,
                                     options.min_pairs));
  }
  r.gt = pick(gt, r.pairs.gt);
  const Trajectory est_paired = pick(est, r.pairs.est);
  r.degenerate = degenerate_alignment(r.gt, est_paired, options.align);
  if (r.degenerate.empty()) {
    r.alignment = solve_alignment(r.gt, est_paired, options.align);
    if (options.align == AlignMode::kSim3 && !(r.alignment.s > 1e-3 && r.alignment.s < 1e3)) {
      r.degenerate = fmt::format("the Sim(3) alignment collapses (scale {:g})", r.alignment.s);
    }
  }
  if (!r.degenerate.empty()) {
    if (!options.allow_degenerate) {
      throw InputError("", "degenerate alignment: " + r.degenerate + " (--allow-degenerate scores it unaligned)");
    }
    r.align = AlignMode::kNone;
    r.alignment = {};
  }
  r.est = apply_alignment(est_paired, r.alignment);

  r.ape_trans_m = ape_translation(r.gt, r.est);
  r.ape_trans_stats = compute_statistics(r.ape_trans_m);
  r.rpe = compute_rpe(r.gt, r.est, options.rpe);
  r.rpe_trans_stats = compute_statistics(r.rpe.trans_m);
  r.rpe_rot_stats = compute_statistics(r.rpe.rot_deg);
  if (options.kitti_metric) r.kitti = kitti_odometry_metric(r.gt, r.est);
  return r;
}

nlohmann::json to_json(const ErrorStatistics& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

nlohmann::json to_json(const EvalResult& r) {
  nlohmann::json j;
  j["pairs"] = r.pairs.size();
  j["coverage"] = r.coverage;
  j["alignment"] = to_string(r.align);
  if (!r.degenerate.empty()) j["degenerate"] = r.degenerate;
  j["ape_trans_m"] = to_json(r.ape_trans_stats);
  j["rpe_trans_m"] = to_json(r.rpe_trans_stats);
  j["rpe_rot_deg"] = to_json(r.rpe_rot_stats);
  if (r.kitti) {
    j["kitti"] = {{"t_rel_percent", r.kitti->t_rel_percent},
                  {"r_rel_deg_per_100m", r.kitti->r_rel_deg_per_100m}};
  }
  return j;
}

std::string format_report(const EvalResult& r) {
  std::string out;
  out += fmt::format("pairs          {} matched {} (ground truth {} poses, estimate {} poses)\n",
                     r.pairs.size(), r.paired_by_index ? "by index" : "by timestamp", r.gt_poses,
                     r.est_poses);
  out += fmt::format("coverage       {:.1f} % of the ground truth's {}\n", 100.0 * r.coverage,
                     r.paired_by_index ? "poses" : "time span");
  out += fmt::format("alignment      {}", to_string(r.align));
  if (r.align == AlignMode::kSim3) out += fmt::format(", scale {:.6f}", r.alignment.s);
  if (!r.degenerate.empty()) out += " (degenerate: " + r.degenerate + "; scored unaligned)";
  out += "\n";
  out += stats_line("APE trans", "m", r.ape_trans_stats);
  const auto& o = r.rpe_options;
  out += fmt::format("RPE delta      {} {}, {} pairs ({} compared)\n", o.delta,
                     o.unit == DeltaUnit::kMeters ? "m" : o.delta == 1.0 ? "frame" : "frames",
                     o.all_pairs ? "all" : "consecutive", r.rpe.pairs.size());
  out += stats_line("RPE trans", "m", r.rpe_trans_stats);
  out += stats_line("RPE rot", "deg", r.rpe_rot_stats);
  if (r.kitti) {
    out += fmt::format("KITTI metric   t_rel {:.4f} %  r_rel {:.4f} deg/100m  ({} segments)\n",
                       r.kitti->t_rel_percent, r.kitti->r_rel_deg_per_100m, r.kitti->segments.size());
  }
  return out;
}

}  // namespace plslam::eval
