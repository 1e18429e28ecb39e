// plslam bench features <dataset>: per-stage timings of the front end on real frames.
//   plslam bench features <dataset> [--frames N] [--json]
// plslam bench slam <dataset>... --out DIR: the paper's experiments (bench_slam_command.h).
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "bench_slam_command.h"
#include "command_registry.h"
#include "commands/dataset_options.h"
#include "json_stdout.h"
#include "plslam/bench/line_benchmark.h"
#include "plslam/bench/point_benchmark.h"
#include "plslam/core/error.h"
#include "plslam/core/sample_stats.h"
#include "plslam/io/frame_stream.h"
#include "plslam/tracking/frame_extractor.h"
#include "stop_signals.h"

namespace plslam::cli {
namespace {

struct BenchFeaturesArgs {
  DatasetArgs dataset;
  bool json = false;
  int n_features = 0;
  int fast_threshold = 7;
  std::string fast_mode = "single";
  std::string fast_impl = "auto";
  double right_factor = 2.0;
};

std::string stage_line(const nlohmann::json& j, const char* key, const char* label) {
  const auto& s = j.at(key);
  return fmt::format("  {:<22} median {:7.3f}  p90 {:7.3f}  ms\n", label, s.at("median").get<double>(),
                     s.at("p90").get<double>());
}

// The whole stereo frame as the tracker gets it (tracking::FrameExtractor: a lines lane and a
// points lane, with their stereo matching), wall clock with the machine's threads.
nlohmann::json frame_benchmark(const io::Dataset& ds, bool kitti) {
  tracking::FrameExtractor extractor(ds.calibration(), kitti ? tracking::FrameExtractorOptions::kitti()
                                                             : tracking::FrameExtractorOptions::euroc());
  std::vector<double> ms;
  io::FrameStream stream(ds);
  long id = 0;
  while (auto f = stream.next()) {
    if (id > 0 && app::stop_requested()) break;
    tracking::FrameTimings t;
    extractor.extract(id++, f->timestamp, f->left, f->right, &t);
    ms.push_back(t.total_ms);
  }
  return summarize(ms);
}

int run_bench_features(const BenchFeaturesArgs& args) {
  // SIGINT/SIGTERM/SIGHUP: each stage stops at its next frame and the frames measured are reported.
  app::install_stop_signals();
  const auto ds = io::open_dataset(args.dataset.path, args.dataset.options());
  const auto stop = [] { return app::stop_requested(); };
  if (ds->size() == 0) throw InputError(args.dataset.path, "no frames selected");
  bench::PointBenchmarkOptions o;
  o.n_features = args.n_features;
  o.orb.fast_mode = features::parse_fast_mode(args.fast_mode);
  o.orb.fast_threshold = args.fast_threshold;
  o.orb.fast_impl = features::parse_fast_impl(args.fast_impl);
  if (!features::fast_impl_available(o.orb.fast_impl))
    throw InputError("", std::string("--fast-impl ") + args.fast_impl + " is not available on this CPU");
  o.right_feature_factor = args.right_factor;
  o.stop = stop;
  if (!(o.right_feature_factor >= 1.0)) throw InputError("", "--right-factor must be >= 1");
  nlohmann::json j = bench::run_point_benchmark(*ds, o);
  // Lines: the same frames, one thread, with OpenCV LSD + LBD timed as the reference.
  const bool kitti = ds->format() == io::DatasetFormat::kKitti;
  bench::LineBenchmarkOptions lo;
  lo.extractor = kitti ? features::LineExtractorOptions::kitti() : features::LineExtractorOptions::euroc();
  // As the SLAM front end keeps them: only lines steep enough for stereo compete for the N places.
  lo.extractor.min_angle_from_horizontal_deg = lo.stereo.min_angle_from_horizontal_deg;
  lo.stop = stop;
  if (!app::stop_requested()) j.update(bench::benchmark_lines(*ds, 0, lo));
  if (!app::stop_requested()) j["frame_ms"] = frame_benchmark(*ds, kitti);
  const bool interrupted = app::stop_requested();
  if (interrupted) {
    // The stages measured so far, marked: a partial benchmark must not pass for a whole one. The
    // table below needs every stage, so a person gets the JSON too.
    j["interrupted_by"] = app::stop_signal_name();
    spdlog::warn("bench: stopped by {}; the stages and frames measured so far follow", app::stop_signal_name());
  }
  if (args.json) {
    print_json(j.dump(2) + "\n");
  } else if (interrupted) {
    std::cout << j.dump(2) << "\n";
  }
  if (args.json || interrupted) return interrupted ? app::stop_exit_code() : 0;
  std::cout << fmt::format("{} ({}), {} frames, {}x{}, {} features, FAST {}, one thread\n", j["dataset"].get<std::string>(),
                           j["format"].get<std::string>(), j["frames"].get<int>(), j["width"].get<int>(),
                           j["height"].get<int>(), j["config"]["n_features"].get<int>(),
                           j["config"]["fast_impl"].get<std::string>())
            << "points, left image:\n"
            << stage_line(j, "pyramid_ms", "pyramid") << stage_line(j, "fast_ms", "FAST")
            << stage_line(j, "ssc_ms", "SSC") << stage_line(j, "quadtree_ms", "quadtree (same input)")
            << stage_line(j, "orb_ms", "orientation+BRIEF") << stage_line(j, "left_extract_ms", "left total (no quadtree)")
            << stage_line(j, "right_extract_ms", "right image extraction") << stage_line(j, "stereo_points_ms", "stereo matching")
            << fmt::format("  SSC speed-up over quadtree  {:.1f}x\n", j["ssc_speedup"].get<double>())
            << fmt::format("  keypoints  FAST {:.0f}  SSC {:.0f}  quadtree {:.0f}  (medians)\n",
                           j["keypoints"]["fast_candidates"]["median"].get<double>(), j["keypoints"]["median"].get<double>(),
                           j["keypoints"]["quadtree"]["median"].get<double>())
            << fmt::format("  stereo matches {:.0f} ({:.1f} % of left keypoints)\n", j["stereo_matches"]["median"].get<double>(),
                           100.0 * j["stereo_matches"]["share"]["median"].get<double>())
            << fmt::format("  uniformity CV (16x12 grid, lower is better)  SSC {:.3f}  quadtree {:.3f}\n",
                           j["uniformity_cv"]["ssc"]["median"].get<double>(),
                           j["uniformity_cv"]["quadtree"]["median"].get<double>())
            << "lines, left image (one thread):\n"
            << stage_line(j, "lsd_ms", "OpenCV LSD") << stage_line(j, "fast_lines_ms", "fast detector")
            << stage_line(j, "merge_ms", "merge + keep N") << stage_line(j, "lbd_ms", "LBD")
            << stage_line(j, "lines_image_ms", "lines total") << stage_line(j, "stereo_lines_ms", "stereo matching")
            << fmt::format("  lines detected {:.0f}, after merge {:.0f}, stereo matches {:.0f}; {:.1f}x faster than "
                           "OpenCV LSD+LBD\n",
                           j["lines_detected"]["median"].get<double>(), j["lines_after_merge"]["median"].get<double>(),
                           j["stereo_line_matches"]["median"].get<double>(), j["lines_speedup_vs_opencv"].get<double>())
            << "whole stereo frame (points and lines, parallel):\n"
            << stage_line(j, "frame_ms", "frame");
  return 0;
}

CommandRegistration register_bench_command({"bench", "Benchmarks: front-end stages (features), whole-system experiments (slam)", [](CLI::App& sub) {
                           sub.require_subcommand(1);
                           auto args = std::make_shared<BenchFeaturesArgs>();
                           CLI::App* features = sub.add_subcommand("features", "Point and line features: per-stage ms, counts, uniformity, whole-frame ms");
                           add_dataset_options(*features, args->dataset, "--frames,--max-frames");
                           features->add_flag("--json", args->json, "Print a JSON object");
                           features->add_option("--features", args->n_features, "Keypoints per image (0: 1200 EuRoC, 2000 KITTI)")
                               ->check(CLI::Range(0, 100000))->capture_default_str();
                           features->add_option("--fast-threshold", args->fast_threshold, "FAST threshold (single mode)")
                               ->check(CLI::Range(1, 254))->capture_default_str();
                           features->add_option("--fast-mode", args->fast_mode, "single | ini_min (20/7 per cell)")
                               ->check(CLI::IsMember({"single", "ini_min"}))->capture_default_str();
                           features->add_option("--fast-impl", args->fast_impl, "FAST code: auto | avx2 | sse2 | scalar | opencv (same corners)")
                               ->check(CLI::IsMember({"auto", "avx2", "sse2", "scalar", "opencv"}))->capture_default_str();
                           features->add_option("--right-factor", args->right_factor, "Right image keeps this many times more points")
                               ->check(CLI::Range(0.1, 100.0))->capture_default_str();
                           auto slam_args = std::make_shared<BenchSlamArgs>();
                           CLI::App* slam = sub.add_subcommand(
                               "slam", "The paper's experiments: configurations x datasets x runs, anchors, report and figures");
                           add_bench_slam_options(*slam, *slam_args);
                           return std::function<int()>([args, features, slam, slam_args] {
                             if (features->parsed()) return run_bench_features(*args);
                             if (slam->parsed()) return run_bench_slam(*slam_args);
                             return 2;
                           });
                         }});

}  // namespace
}  // namespace plslam::cli
