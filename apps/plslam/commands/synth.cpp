// `plslam synth`: render a synthetic stereo sequence with exact ground truth.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "command_registry.h"
#include "plslam/core/error.h"
#include "plslam/core/log.h"
#include "plslam/io/output_folder.h"
#include "plslam/calib/board.h"
#include "plslam/synth/writer.h"
#include "progress_eta.h"
#include "stop_signals.h"

namespace {

struct SynthArgs {
  std::string out;
  std::string scene = "office";
  std::string format;  // default: the preset's own layout
  std::string preset = "euroc";
  int frames = 200;
  std::uint64_t seed = 1;
  std::uint64_t path_seed = 0;
  bool loop = false;
  double loop_overlap = plslam::synth::SequenceOptions{}.loop_overlap;
  double fps = 0;  // 0: the preset's
  bool motion_blur = false;
  std::string motion = "walk";
  std::string camera = "pinhole";
  std::string board = plslam::calib::to_string(plslam::calib::BoardSpec{});
  double fov = 0;  // 0: the preset's focal length
  std::string imu_noise = "none";
  double imu_rate = 200;
  double imu_time_offset = 0;
  bool force = false;
  int threads = 0;
};

namespace fs = std::filesystem;

// The dataset is rendered into a hidden folder beside --out and moved into place when complete, so
// a folder under the requested name is always a whole dataset; an interrupted or failed run
// removes the staging folder.
class StagingFolder {
 public:
  explicit StagingFolder(const fs::path& out)
      : path_(out.parent_path() / fmt::format(".{}.synth-{}", out.filename().string(), ::getpid())) {
    std::error_code ec;
    fs::remove_all(path_, ec);
    plslam::io::prepare_output_folder(path_);
  }
  StagingFolder(const StagingFolder&) = delete;
  StagingFolder& operator=(const StagingFolder&) = delete;
  ~StagingFolder() {
    std::error_code ec;
    if (!committed_) fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

  // Moves the staging folder to `out`; an existing `out` (allowed by --force) is replaced whole.
  void commit(const fs::path& out) {
    std::error_code ec;
    if (fs::exists(out)) {
      const fs::path old = out.parent_path() / fmt::format(".{}.replaced-{}", out.filename().string(), ::getpid());
      fs::rename(out, old, ec);
      if (ec) throw plslam::InputError(out.string(), "cannot move the old folder aside: " + ec.message());
      fs::rename(path_, out, ec);
      if (ec) {
        fs::rename(old, out);
        throw plslam::InputError(out.string(), "cannot move the new dataset into place: " + ec.message());
      }
      fs::remove_all(old, ec);
    } else {
      fs::rename(path_, out, ec);
      if (ec) throw plslam::InputError(out.string(), "cannot move the new dataset into place: " + ec.message());
    }
    committed_ = true;
  }

 private:
  fs::path path_;
  bool committed_ = false;
};

// --out must be absent or an empty folder unless --force: stale files of an older dataset would
// mix with the new one.
fs::path checked_out_folder(const std::string& given, bool force) {
  if (given.empty()) throw plslam::InputError("--out", "empty output folder name");
  fs::path out = fs::absolute(given).lexically_normal();
  if (out.filename().empty()) out = out.parent_path();
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) throw plslam::InputError(out.string(), "is a file, expected an output folder");
    if (!force && !fs::is_empty(out, ec)) {
      throw plslam::InputError(out.string(), "folder is not empty (give --force to replace it)");
    }
  }
  return out;
}

int run_synth(const SynthArgs& o) {
  plslam::synth::SequenceOptions so;
  so.scene = plslam::synth::parse_scene_kind(o.scene);
  so.preset = plslam::synth::parse_preset(o.preset);
  if (o.fps > 0) so.preset.fps = o.fps;
  so.frames = o.frames;
  so.seed = o.seed;
  so.path_seed = o.path_seed;
  so.loop = o.loop;
  so.loop_overlap = o.loop_overlap;
  so.motion_blur = o.motion_blur;
  so.motion = plslam::synth::parse_motion_profile(o.motion);
  so.camera = plslam::synth::parse_camera_kind(o.camera);
  so.fov_deg = o.fov;
  so.board = plslam::calib::parse_board_spec(o.board);
  plslam::synth::ImuSynthOptions imu;
  imu.rate_hz = o.imu_rate;
  imu.noise_scale = plslam::synth::parse_imu_noise(o.imu_noise);
  imu.time_offset = o.imu_time_offset;
  const auto format = plslam::synth::parse_output_format(o.format.empty() ? o.preset : o.format);
  const plslam::synth::Sequence seq(so);  // checks the options first: they are the likelier mistake
  if (format != plslam::synth::OutputFormat::kEuroc && so.camera != plslam::synth::CameraKind::kPinhole) {
    throw plslam::InputError("--camera", fmt::format("a {} camera needs --format euroc: only its sensor.yaml holds a "
                                                     "raw camera's calibration", o.camera));
  }
  const fs::path out = checked_out_folder(o.out, o.force);
  plslam::app::install_stop_signals();
  spdlog::info("synth: {} scene, {} preset ({}x{} @ {:.4g} Hz, baseline {} m), {} frames, path {:.1f} m at {:.2f} m/s{}{}",
               o.scene, so.preset.name, so.preset.width, so.preset.height, so.preset.fps, so.preset.baseline,
               o.frames, seq.path().length(), seq.path().speed(), o.loop ? ", loop" : "",
               so.motion == plslam::synth::MotionProfile::kWalk ? "" : ", " + o.motion + " motion");
  if (so.camera != plslam::synth::CameraKind::kPinhole || so.fov_deg != 0) {
    const auto l = seq.lens(0);
    const double diagonal = std::acos(l.unproject({0, 0})->z()) +
                            std::acos(l.unproject({l.width - 1.0, l.height - 1.0})->z());
    spdlog::info("synth: {} camera, fx {:.2f}, {:.1f} deg diagonal field of view", o.camera, l.fx,
                 diagonal * 180.0 / M_PI);
  }
  if (format == plslam::synth::OutputFormat::kEuroc) {
    spdlog::info("synth: IMU at {} Hz, noise {}{}", imu.rate_hz, o.imu_noise,
                 imu.time_offset != 0 ? fmt::format(", camera clock {:+.4f} s against the IMU's", imu.time_offset) : "");
  }
  if (o.path_seed != 0) {
    const auto v = plslam::synth::path_variation(o.path_seed, seq.scene().vehicle);
    spdlog::info("synth: path seed {}: starts at {:.0f} % of the loop, {}, {:+.2f} m to the left, {:+.2f} m up",
                 o.path_seed, 100 * v.start, v.reverse ? "travelled in reverse" : "same direction", v.lateral, v.height);
  }
  const auto start = std::chrono::steady_clock::now();
  std::size_t last = 0;
  StagingFolder staging(out);
  const bool complete = plslam::synth::write_sequence(
      seq, staging.path(), format,
      [&](std::size_t done, std::size_t total) {
        if (done == total || done >= last + std::max<std::size_t>(1, total / 10)) {
          last = done;
          spdlog::info("synth: {}/{} frames, ETA {:.0f} s", done, total, plslam::cli::eta_seconds(start, done, total));
        }
      },
      o.threads, [] { return plslam::app::stop_requested(); }, imu);
  if (!complete || plslam::app::stop_requested()) {
    spdlog::warn("synth: stopped by {}; nothing written to {}", plslam::app::stop_signal_name(), out.string());
    return plslam::app::stop_exit_code();
  }
  staging.commit(out);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("synth: wrote {} in {:.1f} s", out.string(), s);
  return 0;
}

plslam::cli::CommandRegistration register_synth_command({"synth", "Render a synthetic stereo sequence with exact ground truth",
                                      [](CLI::App& sub) {
                                        auto o = std::make_shared<SynthArgs>();
                                        sub.add_option("--out", o->out, "Output folder")->required();
                                        sub.add_option("--scene", o->scene,
                                                       "office|corridor|street|calibration (a calibration board, "
                                                       "--board, waved in front of the rig: still views, no IMU)")
                                            ->capture_default_str();
                                        sub.add_option("--frames", o->frames, "Number of stereo frames")
                                            ->capture_default_str()
                                            ->check(CLI::Range(2, 1000000));
                                        sub.add_option("--format", o->format,
                                                       "euroc|kitti|video (default: the preset's layout; video: a "
                                                       "side-by-side FFV1 video with its calibration file)");
                                        sub.add_option("--preset", o->preset, "Camera preset: euroc|kitti")
                                            ->capture_default_str();
                                        sub.add_option("--fps", o->fps,
                                                       "Frame rate in Hz (default: the preset's; a lower one renders "
                                                       "the same path with fewer, further-apart frames)")
                                            ->check(CLI::Range(0.5, 1000.0));
                                        sub.add_option("--seed", o->seed, "Seed for textures and motion")
                                            ->check(CLI::NonNegativeNumber)
                                            ->capture_default_str();
                                        sub.add_option("--path-seed", o->path_seed,
                                                       "Another path through the same scene (0: the scene's own): start "
                                                       "point, direction and a small sideways and height offset")
                                            ->check(CLI::NonNegativeNumber)
                                            ->capture_default_str();
                                        auto* loop = sub.add_flag("--loop", o->loop, "Close a loop of >= 30 m and return to the start");
                                        sub.add_option("--loop-overlap", o->loop_overlap,
                                                       "With --loop: share of the path travelled again after the return")
                                            ->check(CLI::Range(0.0, 1.0))
                                            ->capture_default_str()
                                            ->needs(loop);
                                        sub.add_flag("--motion-blur", o->motion_blur, "Blur proportional to the motion");
                                        sub.add_option("--motion", o->motion,
                                                       "walk (the scene's own motion) | handheld (quick looks aside up "
                                                       "to 3 rad/s, hand shake) | drone (fast yaw turns, swoops with "
                                                       "tilt, vibration)")
                                            ->capture_default_str();
                                        sub.add_option("--camera", o->camera,
                                                       "pinhole (an ideal rectified pair) | radtan (EuRoC-like "
                                                       "radial-tangential lenses) | equidistant (TUM-VI-like fisheye "
                                                       "lenses); radtan and equidistant make a real rig: intrinsics "
                                                       "differ per camera, the right one is turned by 0.4 deg")
                                            ->check(CLI::IsMember({"pinhole", "radtan", "equidistant"}))
                                            ->capture_default_str();
                                        sub.add_option("--board", o->board,
                                                       "The calibration scene's board: charuco:COLSxROWS:SQUARE_M:"
                                                       "MARKER_M[:DICT] or chessboard:COLSxROWS:SQUARE_M (squares)")
                                            ->capture_default_str();
                                        sub.add_option("--fov", o->fov,
                                                       "Diagonal field of view in degrees, which sets the focal length "
                                                       "(0: the preset's)")
                                            ->check(CLI::Range(0.0, 220.0))
                                            ->capture_default_str();
                                        sub.add_option("--imu-noise", o->imu_noise,
                                                       "EuRoC layout's IMU: none (exact, zero biases) | euroc (ADIS16448 "
                                                       "noise and random walks, non-zero biases) | F (those scaled by F)")
                                            ->capture_default_str();
                                        sub.add_option("--imu-rate", o->imu_rate, "IMU rate in Hz")
                                            ->check(CLI::Range(1.0, 100000.0))
                                            ->capture_default_str();
                                        sub.add_option("--imu-time-offset", o->imu_time_offset,
                                                       "The camera's clock against the IMU's in seconds (t_cam = t_imu + S)")
                                            ->check(CLI::Range(-0.5, 0.5))
                                            ->capture_default_str();
                                        sub.add_flag("--force", o->force, "Replace a non-empty --out folder");
                                        sub.add_option("--threads", o->threads, "Rendering threads (0: all cores)")
                                            ->check(CLI::Range(0, 1024))
                                            ->capture_default_str();
                                        return std::function<int()>([o] { return run_synth(*o); });
                                      }});

}  // namespace
