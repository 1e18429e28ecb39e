#pragma once
// One call from two trajectories to every error plslam reports: association, alignment, APE,
// RPE and optionally the KITTI metric. Used by `plslam eval` and by benchmark runs.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "plslam/core/types.h"
#include "plslam/eval/alignment.h"
#include "plslam/eval/association.h"
#include "plslam/eval/kitti_metric.h"
#include "plslam/eval/rpe.h"
#include "plslam/eval/statistics.h"

namespace plslam::eval {

struct EvalOptions {
  AlignMode align = AlignMode::kSE3;
  double t_max_diff = 0.01;     // s, for association by time
  bool pair_by_index = false;   // KITTI files: pose i with pose i, timestamps ignored
  RpeOptions rpe;
  bool kitti_metric = false;
  // Refusals (InputError) of an estimate that would score well for the wrong reason. The library
  // defaults refuse nothing beyond 3 pairs; `plslam eval` sets the thresholds below unless
  // --allow-partial / --allow-degenerate lift them.
  double min_coverage = 0.0;    // share of the ground truth's time span (or poses, by index) paired
  std::size_t min_pairs = 3;
  // A ground truth or estimate whose positions all coincide (a failed start writes identity
  // poses), or a Sim(3) scale that collapses, cannot be aligned meaningfully: refuse, or, when
  // allowed, score without alignment and say so.
  bool allow_degenerate = false;
};

struct EvalResult {
  std::size_t gt_poses = 0;
  std::size_t est_poses = 0;
  bool paired_by_index = false;
  IndexPairs pairs;                    // into the input trajectories
  double coverage = 0.0;               // share of the ground truth the pairs span (time, or poses by index)
  std::string degenerate;              // why the alignment was dropped (allow_degenerate), else empty
  AlignMode align = AlignMode::kSE3;
  geometry::AlignmentResult alignment; // estimate -> ground truth
  Trajectory gt;                       // paired ground truth
  Trajectory est;                      // paired and aligned estimate

  std::vector<double> ape_trans_m;
  ErrorStatistics ape_trans_stats;
  RpeErrors rpe;
  ErrorStatistics rpe_trans_stats;
  ErrorStatistics rpe_rot_stats;
  RpeOptions rpe_options;
  std::optional<KittiMetric> kitti;
};

// Throws InputError for fewer than 3 matched pairs and for the other input problems the stages
// report (degenerate alignment, an RPE delta that gives no pair, a ground truth too short for the
// KITTI metric).
EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options);

nlohmann::json to_json(const ErrorStatistics& s);
// {pairs, coverage, alignment[, degenerate], ape_trans_m, rpe_trans_m, rpe_rot_deg[, kitti:
// {t_rel_percent, r_rel_deg_per_100m}]}
nlohmann::json to_json(const EvalResult& r);

// A few aligned lines for a person to read.
std::string format_report(const EvalResult& r);

}  // namespace plslam::eval
