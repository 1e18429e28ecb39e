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
#include "commands/mode_options.h"
#include "plslam/core/build_id.h"
#include "plslam/core/error.h"
#include "plslam/core/stopwatch.h"
#include "plslam/core/version.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/camera_source.h"
#include "plslam/io/frame_stream.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/live_capture.h"
#include "plslam/io/map_export.h"
#include "plslam/io/output_folder.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/io/video_dataset.h"
#include "plslam/system/input_aligned_trajectory.h"
#include "plslam/system/map_file.h"
#include "plslam/system/imu_init_monitor.h"
#include "plslam/system/run_report.h"
#include "plslam/system/slam_system.h"
#include "plslam/system/system_config.h"
#include "plslam/map/map_snapshot.h"
#include "plslam/viz/live_viewer.h"
#include "plslam/viz/scene_document.h"

namespace plslam::cli {
namespace {

namespace fs = std::filesystem;

// Exit code of a run that went to its end but whose result is not usable: tracking never started
// a map, or a --localize run localized under --min-localized of its frames (README: exit codes).
constexpr int kExitNotUsable = 3;


// Marks a run stopped by a signal (README: stats.json); "complete" already says it did not finish.
// Also which build ran where: `bench slam --report-from` checks that collected runs share a build
// and says when their timings come from different hosts.
nlohmann::json with_interruption(nlohmann::json stats) {
  stats["interrupted_by"] = app::stop_requested() ? nlohmann::json(app::stop_signal_name()) : nlohmann::json(nullptr);
  stats["build"] = {{"version", kVersion}, {"build_id", build_id()}, {"host", host_name()}};
  return stats;
}

struct RunArgs {
  DatasetArgs dataset;
  std::string out;
  std::string config;
  std::string vocabulary;
  bool no_place_recognition = false;
  bool no_loop_closing = false;
  bool no_lines = false;
  bool no_imu = false;
  bool quiet = false;
  bool realtime = false;
  ModeArgs mode;
  int repeat = 1;
  std::string save_map;  // --save-map FILE
  std::string load_map;  // --load-map FILE
  bool localize = false; // --localize
  double min_localized = 0.5;  // --min-localized: share of the frames a --localize run must localize
  std::string video;         // --video FILE: side-by-side stereo video
  std::string camera;        // --camera DEVICE: live V4L2 camera (side by side, or the left one)
  std::string camera_right;  // --camera-right DEVICE
  std::string calib;         // --calib FILE, for --video and --camera
  std::string preset;        // --preset euroc|kitti (default: by the dataset's format)
  bool viewer = false;       // --viewer: the browser viewer, live
  viz::ViewerServerOptions viewer_server;  // --port, --host
  double viewer_rate = 5;    // --viewer-rate HZ
  double viewer_linger = 2;  // --viewer-linger S: serving the final state after the run
};

// What a run reads: a dataset (KITTI or EuRoC folders, or a video file), or a live camera.
struct RunInput {
  std::unique_ptr<io::Dataset> dataset;  // null for a live camera
  std::unique_ptr<io::FrameSource> camera;
  StereoCalibration calibration;
  io::DatasetFormat format = io::DatasetFormat::kEuroc;
  std::string name;  // the folder, video file or device, for messages
  // A live camera's --imu (a dataset holds its own, Dataset::imu()). Read and checked, not used yet.
  std::optional<ImuData> camera_imu;
};

// Exactly one input, and the options that belong to it (usage errors, exit 2).
void check_input_args(const RunArgs& a) {
  const int inputs = !a.dataset.path.empty() + !a.video.empty() + !a.camera.empty();
  if (inputs != 1) {
    throw InputError("", inputs == 0 ? "no input: give a dataset folder, --video FILE or --camera DEVICE"
                                     : "give one input only: a dataset folder, --video FILE or --camera DEVICE");
  }
  if (a.dataset.path.empty() && a.calib.empty()) throw InputError("", "--video and --camera need --calib FILE");
  if (a.dataset.path.empty() && a.dataset.format != "auto") throw InputError("", "--format is for dataset folders");
  if (!a.camera.empty() && a.dataset.start != 0) throw InputError("", "--start is not for a live camera");
  check_imu_args(a.dataset);
}

RunInput open_input(const RunArgs& args) {
  RunInput in;
  if (!args.camera.empty()) {
    const io::UserCalibration user = io::read_user_calibration(args.calib);
    const io::InputRectification rect = io::rectify_user_calibration(user, args.dataset.balance, args.calib);
    in.calibration = rect.calibration;
    // The camera's raw frames are the size of the calibration's images, rectified or not.
    StereoCalibration frame_size = in.calibration;
    frame_size.width = user.width();
    frame_size.height = user.height();
    Eigen::Isometry3d T_body_rect = Eigen::Isometry3d::Identity();  // body: the (raw) left camera
    if (rect.rectification) T_body_rect.linear() = rect.rectification->R_rect_left.transpose();
    if (!args.dataset.imu.empty()) {
      // How long the camera runs is not known ahead, so the samples are not cut to its frames.
      in.camera_imu = io::read_imu(args.dataset.imu, args.dataset.imu_calib, T_body_rect);
    }
    in.camera = io::open_stereo_camera(args.camera, args.camera_right, frame_size);
    if (rect.rectification) in.camera = io::rectify_frames(std::move(in.camera), *rect.rectification);
    in.name = in.camera->name();
    return in;
  }
  io::DatasetOptions options = args.dataset.options();
  if (args.video.empty()) options.calibration = args.calib;
  in.dataset = args.video.empty() ? io::open_dataset(args.dataset.path, options)
                                  : io::open_video_dataset(args.video, args.calib, options);
  in.calibration = in.dataset->calibration();
  in.format = in.dataset->format();
  in.name = in.dataset->root().string();
  return in;
}

// What a map file records as the configuration that built it: the preset, the config file's
// text and the switches given on the command line.
std::string map_config_text(const RunArgs& args, io::DatasetFormat preset) {
  nlohmann::json j = {{"preset", preset == io::DatasetFormat::kKitti ? "kitti" : "euroc"},
                      {"config_file", args.config},
                      {"no_lines", args.no_lines},
                      {"no_imu", args.no_imu},
                      {"no_loop_closing", args.no_loop_closing},
                      {"sequential", args.mode.sequential},
                      {"deterministic", !args.mode.sequential && !args.mode.free_running},
                      {"loaded_map", args.load_map}};
  if (!args.config.empty()) {
    std::ifstream in(args.config);
    j["config"] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return j.dump(2);
}

// What stats.json records of the input: where it was (`plslam view` finds the ground truth there)
// and the calibration (the viewer draws frustums of its shape).
nlohmann::json input_json(const RunInput& input) {
  const auto& c = input.calibration;
  nlohmann::json j = {{"name", input.name},
                      {"calibration",
                       {{"width", c.width}, {"height", c.height}, {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx},
                        {"cy", c.cy}, {"baseline", c.baseline}}}};
  if (input.dataset) {
    std::error_code ec;
    const auto root = fs::absolute(input.dataset->root(), ec);
    j["path"] = (ec ? input.dataset->root() : root).string();
    j["format"] = io::to_string(input.format);
  }
  return j;
}

// One run into `out_dir`; its stats.json content is left in `stats_out`.
int run_slam(const RunArgs& args, const fs::path& out_dir, nlohmann::json& stats_out) {
  // Checked before any frame: a bad --out must not be found only when the outputs are written.
  io::prepare_output_folder(out_dir);
  if (!args.save_map.empty()) io::prepare_output_file(args.save_map, "--save-map");
  RunInput input = open_input(args);
  const io::Dataset* ds = input.dataset.get();  // null for a live camera
  // The preset follows the dataset's format (KITTI's for KITTI, EuRoC's otherwise) unless --preset.
  const io::DatasetFormat preset = args.preset.empty() ? input.format : io::parse_dataset_format(args.preset);
  auto options = system::load_system_options(
      preset, args.config.empty() ? std::nullopt : std::optional<fs::path>(args.config));
  if (args.no_lines) options.disable_lines();
  options.sequential = args.mode.sequential;
  options.deterministic = !args.mode.free_running;
  if (!args.vocabulary.empty()) options.vocabulary = args.vocabulary;
  if (args.no_place_recognition) options.place_recognition = false;
  if (args.no_loop_closing) options.loop_closing = false;
  options.localization_only = args.localize;
  const auto vocabulary = system::load_vocabulary(options);  // InputError naming the file
  std::optional<system::MapContents> loaded;
  std::optional<geometry::SE3> gt_anchor;  // of the loaded map
  const auto load_start = std::chrono::steady_clock::now();
  double read_ms = 0;
  if (!args.load_map.empty()) {
    loaded = system::load_map_file(args.load_map);
    system::check_map_matches(loaded->meta, input.calibration, vocabulary.get(), args.load_map);
    read_ms = ms_since(load_start);
  }

  const auto& calib = input.calibration;
  spdlog::info("{}: {}, {}x{}, baseline {:.3f} m, lines {}, place recognition {}", input.name,
               ds ? fmt::format("{} frames, {:.1f} fps", ds->size(), ds->fps()) : std::string("live camera"),
               calib.width, calib.height, calib.baseline, options.extractor.lines ? "on" : "off",
               vocabulary ? fmt::format("on ({} words)", vocabulary->size()) : std::string("off"));

  system::System slam(calib, options, vocabulary);
  // The viewer binds before the first frame: a port in use stops the run before it starts.
  std::unique_ptr<viz::LiveViewer> viewer;
  if (args.viewer) {
    viz::SceneInfo base;
    base.name = input.name;
    base.camera_model = calib;
    viz::LiveViewerOptions viewer_options;
    viewer_options.server = args.viewer_server;
    viewer_options.rate_hz = args.viewer_rate;
    viewer = std::make_unique<viz::LiveViewer>(viewer_options, slam.map(), base);
    std::cout << "viewer: " << viewer->url() << std::endl;
  }
  nlohmann::json map_stats = {{"loaded", args.load_map.empty() ? nlohmann::json(nullptr) : nlohmann::json(args.load_map)},
                               {"localization_only", args.localize},
                               {"min_localized", args.localize ? nlohmann::json(args.min_localized) : nlohmann::json(nullptr)},
                               {"saved", nullptr}};
  if (loaded) {
    gt_anchor = loaded->meta.T_gt_map;
    const auto t0 = std::chrono::steady_clock::now();
    slam.load_map(*loaded);
    const double restore_ms = ms_since(t0);
    map_stats["load"] = {{"keyframes", loaded->keyframes.size()}, {"read_ms", read_ms}, {"restore_ms", restore_ms}};
    spdlog::info("{}: {} keyframes, {} points, {} lines; read in {:.1f} ms, restored in {:.1f} ms", args.load_map,
                 loaded->keyframes.size(), loaded->points.size(), loaded->lines.size(), read_ms, restore_ms);
    loaded.reset();
  }
  system::RunReport report;
  // With an IMU: visual-inertial initialisation, then a gravity-aligned world, tracking with the
  // IMU and its factors in local BA (stereo-inertial). --no-imu: stereo only.
  const ImuData* imu = ds && ds->imu() ? &*ds->imu() : input.camera_imu ? &*input.camera_imu : nullptr;
  const bool imu_used = imu && !args.no_imu && options.use_input_imu;
  if (imu_used) slam.set_imu(*imu);
  app::install_stop_signals();
  std::string fatal;
  const auto start = std::chrono::steady_clock::now();
  auto last_progress = start;
  report.input_frames = ds ? ds->size() : 0;
  std::size_t reached = 0;  // input frames before the one the run stopped at
  std::size_t done = 0;
  std::unique_ptr<io::LiveCapture> live;
  std::vector<double> realtime_lag_ms;  // --realtime: per frame, how late its processing started
  auto process = [&](const io::StereoFrame& frame) {
    const auto r = slam.process(frame);
    report.add(r);
    reached = frame.index + 1;
    ++done;
    const auto now = std::chrono::steady_clock::now();
    if (viewer) {
      viz::LiveFrame v;
      v.frame = r.frame_id;
      v.state = tracking::to_string(r.track.state);
      v.tracked = r.track.tracked;
      if (r.track.tracked && !slam.tracker().records().empty()) {
        const auto anchor = tracking::Tracker::anchor_of(slam.tracker().records().back());
        v.T_wc = anchor.T_cw().inverse();
        if (anchor.keyframe) {
          v.anchor_keyframe = anchor.keyframe->id();
          v.centre_in_anchor = anchor.T_ck.inverse().translation();
        }
      }
      v.loops = slam.loop_closer() ? static_cast<long>(slam.loop_closer()->stats().loops.size()) : 0;
      v.relocalizations = static_cast<long>(slam.tracker().relocalized_frames().size());
      v.frames = static_cast<long>(report.frames);
      v.tracked_frames = static_cast<long>(report.tracked_frames);
      v.fps = static_cast<double>(done) / std::max(1e-9, std::chrono::duration<double>(now - start).count());
      v.local_keyframes = slam.tracker().local_keyframe_ids();
      v.local_points = slam.tracker().local_point_ids();
      v.left = frame.left;  // shares the pixels
      auto features = slam.tracker().last_tracked_features();
      v.tracked_points = std::move(features.points);
      v.tracked_lines = std::move(features.lines);
      viewer->on_frame(std::move(v));
    }
    if (!args.quiet && (now - last_progress > std::chrono::seconds(1) || (ds && done == ds->size()))) {
      last_progress = now;
      const double elapsed = std::chrono::duration<double>(now - start).count();
      spdlog::info("frame {}{}  {:.1f} fps  {}  KF {}  MP {}  ML {}  loops {}{}", done,
                   ds ? fmt::format("/{}", ds->size()) : std::string(), done / elapsed,
                   tracking::to_string(r.track.state), slam.map().num_keyframes(), slam.map().num_points(),
                   slam.map().num_lines(), slam.loop_closer() ? slam.loop_closer()->stats().loops.size() : 0,
                   live ? fmt::format("  dropped {}", live->dropped()) : std::string());
    }
  };
  std::optional<io::FrameStream> stream;
  // With the IMU, blank frames (a black-out, a covered lens) come out of the stream: the IMU carries
  // the camera through those it can (frames.csv state inertial), the others are skipped here.
  if (ds) stream.emplace(*ds, 4, imu_used);
  try {
    while (ds && !app::stop_requested()) {
      auto frame = stream->next();
      if (!frame) {
        reached = report.input_frames = stream->input_frames();  // fewer when a video ended early
        report.complete = true;
        break;
      }
      if (frame->blank && !slam.tracker().can_carry_by_imu(frame->timestamp)) {
        spdlog::warn("skipping frame {}: {}", frame->index, frame->problem);
        report.skipped.push_back({frame->index, frame->timestamp, frame->problem});
        continue;
      }
      if (args.realtime) {
        // Pace the input at the dataset's rate, as a live camera would deliver it. A frame that
        // starts after its time has come is late by the lag: the run is behind real time.
        const double t_rel = frame->timestamp - ds->timestamps().front();
        const auto due = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(t_rel));
        std::this_thread::sleep_until(due);
        realtime_lag_ms.push_back(
            std::max(0.0, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - due).count()));
      }
      process(*frame);
    }
    if (input.camera) {
      // Capturing starts now, with everything loaded: the camera's frames go to the newest-frame
      // slot, and those tracking had no time for are dropped and counted (io/live_capture.h).
      live = std::make_unique<io::LiveCapture>(std::move(input.camera));
      bool blank = false;
      while (!app::stop_requested()) {
        if (args.dataset.max_frames >= 0 && done >= static_cast<std::size_t>(args.dataset.max_frames)) {
          report.complete = true;
          break;
        }
        // A short wait, so that a signal is noticed while the camera delivers nothing.
        auto frame = live->next(std::chrono::milliseconds(100));
        if (!frame) {
          report.complete = live->ended();
          if (report.complete) break;
          continue;
        }
        std::string problem = io::blank_image_problem(frame->left, live->name());
        if (problem.empty()) problem = io::blank_image_problem(frame->right, live->name());
        if (!problem.empty()) {
          if (!blank) spdlog::warn("skipping frame {}: {} (and the blank frames right after it)", frame->index, problem);
          report.skipped.push_back({frame->index, frame->timestamp, std::move(problem)});
          blank = true;
          continue;
        }
        blank = false;
        process(*frame);
      }
    }
  } catch (const InputError& e) {
    fatal = e.what();  // outputs so far are still written below
  }
  nlohmann::json live_stats = nullptr;
  if (live) {
    live->stop();
    report.input_frames = live->captured();
    live_stats = {{"source", live->name()}, {"captured", live->captured()}, {"taken", live->taken()},
                  {"dropped", live->dropped()}};
    const auto log = live->dropped() > 0 ? spdlog::level::warn : spdlog::level::info;
    spdlog::log(log, "{}: {} frames captured, {} taken by tracking, {} dropped (tracking was busy when the next one "
                     "came)",
                live->name(), live->captured(), live->taken(), live->dropped());
  }
  nlohmann::json realtime_stats = nullptr;
  if (args.realtime && ds) {
    realtime_stats = system::realtime_json(realtime_lag_ms, ds->fps());
    spdlog::log(realtime_stats["frames_late"].get<long>() > 0 ? spdlog::level::warn : spdlog::level::info, "{}",
                system::realtime_summary(realtime_stats));
  }
  for (auto& s : stream ? stream->skipped_frames() : std::vector<io::SkippedFrame>{}) {
    // Frames skipped before the stopping point belong to this run; the reader may have run ahead.
    if (s.index < reached) report.skipped.push_back(std::move(s));
  }
  std::sort(report.skipped.begin(), report.skipped.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  if (app::stop_requested()) {
    spdlog::warn("{}: stopping; writing the outputs of the {} frames processed", app::stop_signal_name(), report.frames);
  }
  slam.finish();
  report.settle(slam.tracker().records());

  if (!args.save_map.empty() && slam.map().first_keyframe()) {
    // After local mapping and loop closing (and its global BA) finished: the map as it ends.
    const auto t0 = std::chrono::steady_clock::now();
    system::MapFileMeta meta;
    meta.created_by = fmt::format("plslam {} run {}", kVersion, input.name);
    meta.config = map_config_text(args, preset);
    if (gt_anchor) {
      meta.T_gt_map = gt_anchor;  // a loaded map keeps the anchor it came with
    } else if (const auto* first = slam.map().first_keyframe(); ds && first && !first->is_bad()) {
      meta.T_gt_map = system::ground_truth_anchor(*ds, *first);
    }
    const auto contents = slam.capture_map(std::move(meta));
    system::save_map_file(args.save_map, contents);
    map_stats["saved"] = args.save_map;
    map_stats["save"] = {{"keyframes", contents.keyframes.size()}, {"ms", ms_since(t0)}};
    spdlog::info("map saved to {} ({:.1f} ms)", args.save_map, ms_since(t0));
  }

  if (!slam.initialized_at()) {
    // No pose was ever tracked: an identity trajectory would look perfect to an evaluator, so
    // none is written; stats.json says what happened.
    stats_out = with_interruption(report.to_json(slam));
    stats_out["map"] = map_stats;
    stats_out["live"] = live_stats;
    stats_out["realtime"] = realtime_stats;
    const auto stats_text = stats_out.dump(2);
    io::write_file_atomically(out_dir / "stats.json", [&](std::ostream& o) { o << stats_text << "\n"; });
    if (viewer) {
      viz::Scene empty;  // the page says so instead of waiting for a map that never came
      empty.info.source = "run";
      empty.info.name = out_dir.string();
      empty.info.state = "not initialised";
      empty.info.frames = static_cast<long>(report.frames);
      viewer->finish(empty);
    }
    if (!fatal.empty()) throw InputError("", fatal);
    if (app::stop_requested()) return app::stop_exit_code();
    if (!args.load_map.empty()) {
      std::cerr << fmt::format("plslam: error: {}: the camera was never found in the map {} in {} frames; "
                               "no trajectory written\n",
                               input.name, args.load_map, report.frames);
    } else {
      std::cerr << fmt::format(
          "plslam: error: {}: tracking never initialised in {} frames (no frame had {} stereo points); "
          "no trajectory written\n",
          input.name, report.frames, options.tracker.init_min_points);
    }
    return kExitNotUsable;
  }

  const auto traj = slam.tracked_trajectory();
  io::write_trajectory(out_dir / "trajectory.tum", traj, io::TrajectoryFormat::kTum);
  if (ds) {
    // One line per input frame needs every input frame's time: a live camera has none for the
    // frames it dropped, and no format pairing poses by line.
    const std::vector<double> reached_times(ds->timestamps().begin(),
                                            ds->timestamps().begin() + static_cast<std::ptrdiff_t>(reached));
    const auto aligned = system::align_to_input(slam.tracker().records(), reached_times);
    report.untracked_lines = aligned.untracked;
    if (ds->format() == io::DatasetFormat::kKitti) {
      io::write_trajectory(out_dir / "trajectory.kitti", aligned.poses, io::TrajectoryFormat::kKitti);
    }
  }
  io::write_trajectory(out_dir / "keyframes.tum", slam.keyframe_trajectory(), io::TrajectoryFormat::kTum);
  io::write_file_atomically(out_dir / "frames.csv", [&](std::ostream& o) { report.write_frames_csv(o); });
  std::vector<Eigen::Vector3d> points;
  for (const auto* p : slam.map().points()) points.push_back(p->position());
  io::write_ply_points(out_dir / "map_points.ply", points);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines;
  for (const auto* l : slam.map().lines()) lines.emplace_back(l->start(), l->end());
  io::write_ply_lines(out_dir / "map_lines.ply", lines);
  // The keyframes with their graph, for `plslam view` (the PLY files hold the points and lines).
  const auto graph = viz::map_graph_json(map::take_snapshot(slam.map())).dump();
  io::write_file_atomically(out_dir / "map_graph.json", [&](std::ostream& o) { o << graph << "\n"; });

  auto stats = with_interruption(report.to_json(slam));
  stats["map"] = map_stats;
  stats["live"] = live_stats;
  stats["realtime"] = realtime_stats;
  stats["input"] = input_json(input);
  stats["imu"] = slam.imu_report();
  if (const auto* imu_init = slam.imu_init()) {
    spdlog::info("{}", imu_init->summary());
    if (const auto& g = slam.gravity_alignment()) {
      spdlog::info("world: gravity-aligned (z up) from frame {} on; every output is in it", g->from_frame);
    }
    spdlog::info("{}", slam.imu_summary());
  }
  if (ds && ds->ground_truth()) {
    // Tracked poses only: a prediction made while lost is not an estimate to score.
    try {
      const auto accuracy = system::evaluate_against_ground_truth(*ds, traj);
      stats["accuracy"] = accuracy;
      std::cout << system::format_accuracy(accuracy);
      // Is the pose covariance (frames.csv cov_*) consistent with the errors? 6 when it is.
      const auto nees = system::motion_nees_json(*ds, report.covariant_poses(traj));
      stats["accuracy"]["motion_nees"] = nees;
      if (nees["motions"].get<std::size_t>() > 0) {
        std::cout << fmt::format("pose covariance: mean NEES {:.2f} (median {:.2f}) of {} frame-to-frame motions, "
                                 "6 if consistent\n",
                                 nees["mean"].get<double>(), nees["median"].get<double>(),
                                 nees["motions"].get<std::size_t>());
      }
    } catch (const InputError& e) {
      // Too few tracked poses to score (or a degenerate alignment): say so instead of a number.
      spdlog::warn("no accuracy: {}", e.what());
      stats["accuracy"] = {{"error", e.what()}};
    }
    if (gt_anchor) {
      // Same ground-truth world as the run that made the map: positions in the map's frame,
      // with no alignment, are the localization error itself.
      try {
        const auto in_map = system::evaluate_in_map_frame(*ds, traj, *gt_anchor);
        stats["accuracy_in_map_frame"] = in_map;
        std::cout << fmt::format("position error in the map's frame (no alignment): rmse {:.4f} m over {} poses\n",
                                 in_map["ape_trans_m"]["rmse"].get<double>(), in_map["pairs"].get<std::size_t>());
      } catch (const InputError& e) {
        stats["accuracy_in_map_frame"] = {{"error", e.what()}};
      }
    }
  }
  io::write_file_atomically(out_dir / "stats.json", [&](std::ostream& o) { o << stats.dump(2) << "\n"; });
  stats_out = stats;
  // A signal while the viewer lingers on a finished run does not make the run interrupted.
  int rc = app::stop_requested() ? app::stop_exit_code() : 0;
  std::cout << report.summary(slam);
  if (rc == 0 && args.localize && fatal.empty()) {
    const std::size_t localized = report.count(tracking::FrameState::kLocalized);
    const double share = report.frames ? static_cast<double>(localized) / static_cast<double>(report.frames) : 0.0;
    if (share < args.min_localized) {
      std::cerr << fmt::format("plslam: error: {}: localized {} of {} frames ({:.0f} %) in the map {}, under "
                               "--min-localized {}; the outputs are written, but the result is not usable\n",
                               input.name, localized, report.frames, 100.0 * share, args.load_map, args.min_localized);
      rc = kExitNotUsable;
    }
  }
  spdlog::info("outputs written to {}", out_dir.string());
  if (viewer) {
    // The page ends on exactly what `plslam view` shows of these outputs.
    viewer->finish(viz::scene_from_run_folder(out_dir));
    if (args.viewer_linger > 0 && !app::stop_requested()) {
      spdlog::info("viewer: serving the final state for {:.0f} s more", args.viewer_linger);
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(args.viewer_linger);
      while (std::chrono::steady_clock::now() < until && !app::stop_requested()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
  }
  if (!fatal.empty()) throw InputError("", fatal);
  return rc;
}

// --repeat N: N runs into DIR/run-1 ... DIR/run-N, and DIR/repeat.json with the ATE of each and
// their median, min, max and max/min, so that the run-to-run spread is visible wherever an
// accuracy is quoted. Stops at the first failing or interrupted run.
int run_repeated(const RunArgs& args) {
  const fs::path out_dir = args.out;
  io::prepare_output_folder(out_dir);
  std::vector<double> ates;
  nlohmann::json runs = nlohmann::json::array();
  int rc = 0;
  for (int i = 1; i <= args.repeat && rc == 0 && !app::stop_requested(); ++i) {
    const fs::path dir = out_dir / fmt::format("run-{}", i);
    spdlog::info("run {}/{} -> {}", i, args.repeat, dir.string());
    nlohmann::json stats;
    rc = run_slam(args, dir, stats);
    nlohmann::json entry = {{"run", i}, {"folder", dir.filename().string()}, {"exit_code", rc}};
    if (stats.contains("accuracy") && stats["accuracy"].contains("ape_trans_m")) {
      const double ate = stats["accuracy"]["ape_trans_m"]["rmse"].get<double>();
      entry["ate_rmse_m"] = ate;
      if (rc == 0) ates.push_back(ate);
    }
    if (stats.contains("keyframes")) entry["keyframes"] = stats["keyframes"];
    runs.push_back(entry);
  }
  nlohmann::json summary = {{"runs", runs}, {"requested", args.repeat}, {"completed_runs", ates.size()}};
  if (!ates.empty()) {
    std::vector<double> sorted = ates;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    summary["ate_rmse_m"] = {{"median", median}, {"min", sorted.front()}, {"max", sorted.back()},
                             {"max_over_min", sorted.front() > 0 ? sorted.back() / sorted.front() : 0.0}};
    std::cout << fmt::format("ATE over {} runs: median {:.4f} m, min {:.4f}, max {:.4f} (max/min {:.2f})\n", n, median,
                             sorted.front(), sorted.back(), sorted.front() > 0 ? sorted.back() / sorted.front() : 0.0);
  } else {
    std::cout << "no ATE: the dataset has no ground truth, or no run completed\n";
  }
  io::write_file_atomically(out_dir / "repeat.json", [&](std::ostream& o) { o << summary.dump(2) << "\n"; });
  return rc;
}

CommandRegistration register_run_command({"run", "Run stereo point-line SLAM on a sequence", [](CLI::App& sub) {
                           auto args = std::make_shared<RunArgs>();
                           add_dataset_options(sub, args->dataset, "--max-frames", false);
                           sub.add_option("--out", args->out, "Output folder")->required();
                           sub.add_option("--video", args->video,
                                          "Side-by-side stereo video (left | right halves, rectified) instead of a "
                                          "dataset folder; a ground_truth.tum beside it is used");
                           auto* camera = sub.add_option("--camera", args->camera,
                                                         "Live V4L2 camera, e.g. /dev/video0: side-by-side frames, "
                                                         "or the left camera with --camera-right (a video file is "
                                                         "played at its frame rate, as a camera would deliver it)");
                           sub.add_option("--camera-right", args->camera_right, "The right camera's device")
                               ->needs(camera);
                           sub.add_option("--calib", args->calib,
                                          "Stereo calibration: of the rectified images (YAML: width height fx fy cx "
                                          "cy baseline), or of the raw cameras as plslam calibrate writes it (Kalibr's "
                                          "camchain.yaml). Needed for --video and --camera; for an EuRoC folder it "
                                          "replaces the two sensor.yaml");
                           add_imu_options(sub, args->dataset);
                           sub.add_option("--preset", args->preset,
                                          "Configuration preset (default: kitti for KITTI datasets, else euroc)")
                               ->check(CLI::IsMember({"euroc", "kitti"}));
                           sub.add_option("--config", args->config,
                                          "YAML configuration (default: the preset for the dataset format)");
                           sub.add_option("--vocabulary", args->vocabulary,
                                          "Vocabulary file for place recognition (default: the one in data/vocabulary)");
                           sub.add_flag("--no-place-recognition", args->no_place_recognition,
                                        "No relocalization: a lost camera starts a new map segment");
                           sub.add_flag("--no-loop-closing", args->no_loop_closing,
                                        "No loop closing (odometry with local mapping only)");
                           sub.add_flag("--no-lines", args->no_lines, "Points only");
                           sub.add_flag("--no-imu", args->no_imu, "Stereo only: leave the input's IMU unused");
                           sub.add_flag("--quiet", args->quiet, "No progress lines");
                           sub.add_flag("--realtime", args->realtime, "Pace the input at the dataset's frame rate")
                               ->excludes(camera);
                           add_mode_flags(
                               sub, args->mode,
                               "Run local mapping and loop closing in the tracking thread (the debugging mode)",
                               "The default: the threads meet at frames fixed in advance, so runs are identical "
                               "to each other (local mapping beside the next frame's extraction)",
                               "The threads meet whenever they are done: runs differ, and local mapping skips BAs "
                               "when it falls behind (the pipeline before the deterministic one)");
                           sub.add_option("--save-map", args->save_map,
                                          "Save the map at the end (after loop closing) to FILE (.plmap)");
                           auto* load = sub.add_option("--load-map", args->load_map,
                                                       "Start in the map of FILE: relocalize in it, then keep mapping it");
                           auto* localize = sub.add_flag("--localize", args->localize,
                                        "With --load-map: localization only (no new keyframes, points or lines)")
                               ->needs(load);
                           sub.add_option("--min-localized", args->min_localized,
                                          "With --localize: exit 3 (outputs still written) when under this share of "
                                          "the frames is localized")
                               ->check(CLI::Range(0.0, 1.0))
                               ->capture_default_str()
                               ->needs(localize);
                           sub.footer(
                               "Exit codes: 0 done; 2 bad usage or input (one line naming the file); 3 ran to the end "
                               "but the result is not usable (no map was ever started, or --localize localized under "
                               "--min-localized of the frames; the outputs are still written); 128 + N stopped by "
                               "signal N (the outputs so far are written); 1 internal error. trajectory.tum holds only "
                               "the poses plslam stands behind (frames.csv state tracked, relocalized or localized).");
                           sub.add_option("--repeat", args->repeat,
                                          "Run N times into DIR/run-1..N and report the ATE's median, min and max")
                               ->check(CLI::Range(1, 1000))
                               ->excludes(camera);
                           sub.add_flag("--viewer", args->viewer,
                                        "Serve the browser viewer live during the run (prints its URL)");
                           sub.add_option("--port", args->viewer_server.port, "--viewer's TCP port (0: any free one)")
                               ->capture_default_str();
                           sub.add_option("--host", args->viewer_server.host,
                                          "--viewer's address; 0.0.0.0 serves every network, an explicit choice")
                               ->capture_default_str();
                           sub.add_option("--viewer-rate", args->viewer_rate, "--viewer's updates per second")
                               ->capture_default_str();
                           sub.add_option("--viewer-linger", args->viewer_linger,
                                          "--viewer: seconds the final state stays served after the run")
                               ->capture_default_str();
                           return std::function<int()>([args, &sub] {
                             const bool viewer_options = sub.count("--port") + sub.count("--host") +
                                                         sub.count("--viewer-rate") + sub.count("--viewer-linger") > 0;
                             if (viewer_options && !args->viewer) {
                               throw InputError("", "--port, --host, --viewer-rate and --viewer-linger need --viewer");
                             }
                             if (args->viewer && args->repeat > 1) throw InputError("", "--viewer is for one run, not --repeat");
                             if (!(args->viewer_linger >= 0)) throw InputError("", "--viewer-linger must be >= 0");
                             check_input_args(*args);
                             if (args->repeat > 1) return run_repeated(*args);
                             nlohmann::json stats;
                             return run_slam(*args, args->out, stats);
                           });
                         }});

}  // namespace
}  // namespace plslam::cli
