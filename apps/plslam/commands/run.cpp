// plslam run <dataset> --out DIR: stereo point-line SLAM over a sequence, with progress output,
// trajectory/map/statistics files, and ATE/RPE against the ground truth when there is one.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "stop_signals.h"
#include "commands/dataset_options.h"
#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/frame_stream.h"
#include "plslam/io/map_export.h"
#include "plslam/io/output_folder.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/system/input_aligned_trajectory.h"
#include "plslam/system/run_report.h"
#include "plslam/system/slam_system.h"
#include "plslam/system/system_config.h"

namespace plslam::cli {
namespace {

namespace fs = std::filesystem;

// Exit code of a run in which tracking never started a map (README: exit codes).
constexpr int kExitNotInitialized = 3;


// Marks a run stopped by a signal (README: stats.json); "complete" already says it did not finish.
nlohmann::json with_interruption(nlohmann::json stats) {
  stats["interrupted_by"] = app::stop_requested() ? nlohmann::json(app::stop_signal_name()) : nlohmann::json(nullptr);
  return stats;
}

struct RunArgs {
  DatasetArgs dataset;
  std::string out;
  std::string config;
  bool no_lines = false;
  bool quiet = false;
  bool realtime = false;
  bool sequential = false;
};

int run_slam(const RunArgs& args) {
  // Checked before any frame: a bad --out must not be found only when the outputs are written.
  const fs::path out_dir = args.out;
  io::prepare_output_folder(out_dir);
  const auto ds = io::open_dataset(args.dataset.path, args.dataset.options());
  auto options = system::load_system_options(
      ds->format(), args.config.empty() ? std::nullopt : std::optional<fs::path>(args.config));
  if (args.no_lines) options.disable_lines();
  options.sequential = args.sequential;

  spdlog::info("{}: {} frames, {}x{}, {:.1f} fps, baseline {:.3f} m, lines {}", ds->root().string(), ds->size(),
               ds->calibration().width, ds->calibration().height, ds->fps(), ds->calibration().baseline,
               options.extractor.lines ? "on" : "off");

  system::System slam(ds->calibration(), options);
  system::RunReport report;
  app::install_stop_signals();
  std::string fatal;
  const auto start = std::chrono::steady_clock::now();
  auto last_progress = start;
  report.input_frames = ds->size();
  std::size_t reached = 0;  // input frames before the one the run stopped at
  io::FrameStream stream(*ds);
  try {
    std::size_t done = 0;
    while (!app::stop_requested()) {
      auto frame = stream.next();
      if (!frame) {
        reached = ds->size();
        report.complete = true;
        break;
      }
      if (args.realtime && done > 0) {
        // Pace the input at the dataset's rate, as a live camera would deliver it.
        const double t_rel = frame->timestamp - ds->timestamps().front();
        std::this_thread::sleep_until(start + std::chrono::duration<double>(t_rel));
      }
      const auto r = slam.process(*frame);
      report.add(r);
      reached = frame->index + 1;
      ++done;
      const auto now = std::chrono::steady_clock::now();
      if (!args.quiet && (now - last_progress > std::chrono::seconds(1) || done == ds->size())) {
        last_progress = now;
        const double elapsed = std::chrono::duration<double>(now - start).count();
        spdlog::info("frame {}/{}  {:.1f} fps  {}  KF {}  MP {}  ML {}", done, ds->size(), done / elapsed,
                     tracking::to_string(r.track.state), slam.map().num_keyframes(), slam.map().num_points(),
                     slam.map().num_lines());
      }
    }
  } catch (const InputError& e) {
    fatal = e.what();  // outputs so far are still written below
  }
  for (auto& s : stream.skipped_frames()) {
    // Frames skipped before the stopping point belong to this run; the reader may have run ahead.
    if (s.index < reached) report.skipped.push_back(std::move(s));
  }
  if (app::stop_requested()) {
    spdlog::warn("{}: stopping; writing the outputs of the {} frames processed", app::stop_signal_name(), report.frames);
  }
  slam.finish();

  if (!slam.initialized_at()) {
    // No pose was ever tracked: an identity trajectory would look perfect to an evaluator, so
    // none is written; stats.json says what happened.
    const auto stats_text = with_interruption(report.to_json(slam)).dump(2);
    io::write_file_atomically(out_dir / "stats.json", [&](std::ostream& o) { o << stats_text << "\n"; });
    if (!fatal.empty()) throw InputError("", fatal);
    if (app::stop_requested()) return app::stop_exit_code();
    std::cerr << fmt::format(
        "plslam: error: {}: tracking never initialised in {} frames (no frame had {} stereo points); "
        "no trajectory written\n",
        ds->root().string(), report.frames, options.tracker.init_min_points);
    return kExitNotInitialized;
  }

  const auto traj = slam.tracked_trajectory();
  io::write_trajectory(out_dir / "trajectory.tum", traj, io::TrajectoryFormat::kTum);
  const std::vector<double> reached_times(ds->timestamps().begin(),
                                          ds->timestamps().begin() + static_cast<std::ptrdiff_t>(reached));
  const auto aligned = system::align_to_input(slam.tracker().records(), reached_times);
  report.untracked_lines = aligned.untracked;
  if (ds->format() == io::DatasetFormat::kKitti) {
    io::write_trajectory(out_dir / "trajectory.kitti", aligned.poses, io::TrajectoryFormat::kKitti);
  }
  io::write_trajectory(out_dir / "keyframes.tum", slam.keyframe_trajectory(), io::TrajectoryFormat::kTum);
  std::vector<Eigen::Vector3d> points;
  for (const auto* p : slam.map().points()) points.push_back(p->position());
  io::write_ply_points(out_dir / "map_points.ply", points);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines;
  for (const auto* l : slam.map().lines()) lines.emplace_back(l->start(), l->end());
  io::write_ply_lines(out_dir / "map_lines.ply", lines);

  auto stats = with_interruption(report.to_json(slam));
  if (ds->ground_truth()) {
    // Tracked poses only: a prediction made while lost is not an estimate to score.
    try {
      const auto accuracy = system::evaluate_against_ground_truth(*ds, traj);
      stats["accuracy"] = accuracy;
      std::cout << system::format_accuracy(accuracy);
    } catch (const InputError& e) {
      // Too few tracked poses to score (or a degenerate alignment): say so instead of a number.
      spdlog::warn("no accuracy: {}", e.what());
      stats["accuracy"] = {{"error", e.what()}};
    }
  }
  io::write_file_atomically(out_dir / "stats.json", [&](std::ostream& o) { o << stats.dump(2) << "\n"; });
  std::cout << report.summary(slam);
  spdlog::info("outputs written to {}", out_dir.string());
  if (!fatal.empty()) throw InputError("", fatal);
  return app::stop_requested() ? app::stop_exit_code() : 0;
}

CommandRegistration reg({"run", "Run stereo point-line SLAM on a sequence", [](CLI::App& sub) {
                           auto args = std::make_shared<RunArgs>();
                           add_dataset_options(sub, args->dataset);
                           sub.add_option("--out", args->out, "Output folder")->required();
                           sub.add_option("--config", args->config,
                                          "YAML configuration (default: the preset for the dataset format)");
                           sub.add_flag("--no-lines", args->no_lines, "Points only");
                           sub.add_flag("--quiet", args->quiet, "No progress lines");
                           sub.add_flag("--realtime", args->realtime, "Pace the input at the dataset's frame rate");
                           sub.add_flag("--sequential", args->sequential,
                                        "Run local mapping in the tracking thread (reproducible runs)");
                           return std::function<int()>([args] { return run_slam(*args); });
                         }});

}  // namespace
}  // namespace plslam::cli
