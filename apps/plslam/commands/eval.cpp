// `plslam eval`: APE, RPE and the KITTI metric of an estimated trajectory against ground truth,
// with evo's association and definitions.
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "json_stdout.h"
#include "plslam/core/error.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/eval/evaluate.h"
#include "plslam/eval/plots.h"
#include "plslam/io/trajectory_io.h"

namespace {

struct Options {
  std::string gt, est;
  std::string gt_format = "auto", est_format = "auto";
  std::string gt_body_to_cam;
  double t_max_diff = 0.01;
  std::string align = "se3";
  double rpe_delta = 1.0;
  std::string rpe_unit = "frames";
  bool all_pairs = false;
  bool kitti_metric = false;
  bool json = false;
  std::string plot_dir;
  std::string frames;  // frames.csv of the run, for tracking.png
  bool allow_partial = false;
  bool allow_degenerate = false;
};

// An estimate is scored only when it pairs with at least this share of the ground truth, in at
// least this many poses: a run that lost track after a few frames would otherwise report an
// excellent error over the few poses it has. An interrupted run's half trajectory still scores.
constexpr double kMinCoverage = 0.2;
constexpr std::size_t kMinPairs = 10;

plslam::io::TrajectoryFormat resolve_format(const std::string& name, const std::string& path) {
  if (name == "auto") return plslam::io::detect_trajectory_format(path);
  return plslam::io::parse_trajectory_format(name);
}

int run(const Options& o) {
  if (!o.frames.empty() && o.plot_dir.empty()) throw plslam::InputError(o.frames, "--frames needs --plot DIR");
  using plslam::io::TrajectoryFormat;
  const TrajectoryFormat gt_format = resolve_format(o.gt_format, o.gt);
  const TrajectoryFormat est_format = resolve_format(o.est_format, o.est);
  // KITTI rotations as written, as evo and the devkit use them, so the numbers agree with theirs.
  constexpr auto kAsWritten = plslam::io::KittiRotation::kAsWritten;
  plslam::Trajectory gt = plslam::io::read_trajectory(o.gt, gt_format, nullptr, kAsWritten);
  plslam::Trajectory est = plslam::io::read_trajectory(o.est, est_format, nullptr, kAsWritten);
  if (!o.gt_body_to_cam.empty()) {
    gt = plslam::io::body_to_sensor(gt, plslam::io::read_euroc_T_BS(o.gt_body_to_cam));
  }

  plslam::eval::EvalOptions options;
  options.align = plslam::eval::parse_align_mode(o.align);
  options.t_max_diff = o.t_max_diff;
  options.rpe.delta = o.rpe_delta;
  options.rpe.unit = o.rpe_unit == "m" ? plslam::eval::DeltaUnit::kMeters : plslam::eval::DeltaUnit::kFrames;
  options.rpe.all_pairs = o.all_pairs;
  options.kitti_metric = o.kitti_metric;
  if (!o.allow_partial) {
    options.min_coverage = kMinCoverage;
    options.min_pairs = kMinPairs;
  }
  options.allow_degenerate = o.allow_degenerate;

  // KITTI files carry no times: such a pair is matched pose by pose. When only one side is KITTI
  // the other's stamps cannot be matched against anything, so index pairing needs equal lengths,
  // and the stamped side lends its times to the plots.
  const bool gt_kitti = gt_format == TrajectoryFormat::kKitti;
  const bool est_kitti = est_format == TrajectoryFormat::kKitti;
  options.pair_by_index = gt_kitti || est_kitti;
  if (gt_kitti != est_kitti) {
    if (gt.size() != est.size()) {
      throw plslam::InputError(gt_kitti ? o.gt : o.est,
                               fmt::format("KITTI format has no timestamps, so poses pair by index, "
                                           "but the ground truth has {} poses and the estimate {}; "
                                           "convert the KITTI file to TUM with its times",
                                           gt.size(), est.size()));
    }
    auto& kitti = gt_kitti ? gt : est;
    const auto& stamped = gt_kitti ? est : gt;
    for (std::size_t i = 0; i < kitti.size(); ++i) kitti[i].t = stamped[i].t;
    spdlog::info("one trajectory is in KITTI format: pairing poses by index");
  }

  const auto result = plslam::eval::evaluate(gt, est, options);
  spdlog::info("matched {} pose pairs {} ({} ground-truth poses, {} estimated): the estimate covers {:.1f} % of "
               "the ground truth", result.pairs.size(),
               options.pair_by_index ? "by index" : fmt::format("by timestamp (max diff {} s)", o.t_max_diff),
               gt.size(), est.size(), 100.0 * result.coverage);
  if (!result.degenerate.empty()) spdlog::warn("degenerate alignment ({}): scored without alignment", result.degenerate);

  if (!o.plot_dir.empty()) {
    plslam::eval::PlotOptions plot_options;
    plot_options.x_is_frame = gt_kitti && est_kitti;
    for (const auto& p : plslam::eval::write_plots(result, o.plot_dir, plot_options)) {
      spdlog::info("wrote {}", p.string());
    }
    if (!o.frames.empty()) {
      const auto log = plslam::eval::read_frame_log(o.frames);
      const auto p = plslam::eval::write_tracking_plot(result, log, o.plot_dir, plot_options);
      spdlog::info("wrote {}", p.string());
      if (plslam::eval::has_resource_columns(log)) {
        spdlog::info("wrote {}", plslam::eval::write_resources_plot(log, o.plot_dir).string());
      }
    }
  }
  if (o.json) {
    plslam::cli::print_json(plslam::eval::to_json(result).dump(2) + "\n");
  } else {
    std::cout << plslam::eval::format_report(result);
  }
  return 0;
}

plslam::cli::CommandRegistration register_eval_command({"eval", "Evaluate an estimated trajectory against ground truth (APE, RPE, KITTI metric)",
  [](CLI::App& sub) {
    auto o = std::make_shared<Options>();
    const std::vector<std::string> formats = {"tum", "kitti", "euroc", "auto"};
    sub.add_option("--gt", o->gt, "Ground-truth trajectory file")->required();
    sub.add_option("--est", o->est, "Estimated trajectory file")->required();
    sub.add_option("--gt-format", o->gt_format, "tum|kitti|euroc|auto")
        ->check(CLI::IsMember(formats))->capture_default_str();
    sub.add_option("--est-format", o->est_format, "tum|kitti|euroc|auto")
        ->check(CLI::IsMember(formats))->capture_default_str();
    sub.add_option("--gt-body-to-cam", o->gt_body_to_cam,
                   "EuRoC camera sensor.yaml: turn body-frame ground truth into camera poses (T_w_body * T_BS)")
        ->check(CLI::ExistingFile);
    sub.add_option("--t-max-diff", o->t_max_diff, "Max timestamp difference for association [s]")
        ->check(CLI::NonNegativeNumber)->capture_default_str();
    sub.add_option("--align", o->align, "se3|sim3|none (Umeyama)")
        ->check(CLI::IsMember({"se3", "sim3", "none"}))->capture_default_str();
    sub.add_option("--rpe-delta", o->rpe_delta, "RPE delta, in --rpe-unit")
        ->check(CLI::PositiveNumber)->capture_default_str();
    sub.add_option("--rpe-unit", o->rpe_unit, "frames|m")
        ->check(CLI::IsMember({"frames", "m"}))->capture_default_str();
    sub.add_flag("--all-pairs", o->all_pairs, "RPE over all pairs instead of consecutive ones");
    sub.add_flag("--kitti-metric", o->kitti_metric, "Also compute the KITTI odometry metric");
    sub.add_flag("--json", o->json, "Print the results as JSON on stdout");
    sub.add_flag("--allow-partial", o->allow_partial,
                 "Score an estimate covering under 20 % of the ground truth, or with under 10 pose pairs");
    sub.add_flag("--allow-degenerate", o->allow_degenerate,
                 "Score, unaligned, an estimate or ground truth whose positions all coincide, or a collapsing Sim(3)");
    sub.add_option("--plot", o->plot_dir, "Write trajectory.png, ape.png and rpe.png into DIR");
    sub.add_option("--frames", o->frames,
                   "With --plot: the run's frames.csv, plotted in tracking.png next to the APE (inliers, keyframes, local map)");
    return std::function<int()>([o] { return run(*o); });
  }});

}  // namespace
