// plslam calibrate: a stereo rig's lenses and the pose between them from a board moved in front
// of it (calib/stereo_calibration.h), written as a calibration file `plslam run --calib` reads
// and as an EuRoC layout's two sensor.yaml, with a report and a coverage image.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>
#include <tbb/parallel_invoke.h>

#include "command_registry.h"
#include "json_stdout.h"
#include "progress_eta.h"
#include "stop_signals.h"
#include "plslam/calib/board.h"
#include "plslam/calib/calibration_report.h"
#include "plslam/calib/stereo_calibration.h"
#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/camchain_file.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/output_folder.h"
#include "plslam/io/raw_stereo_input.h"

namespace plslam::cli {
namespace {

namespace fs = std::filesystem;

struct CalibrateArgs {
  io::RawStereoInputSpec input;
  std::string board = "charuco:10x7:0.06:0.045:5x5_100";
  std::string model = "radtan";
  std::string out;
  std::string print_board;
  int every = 1;
  int max_views = 40;
  bool json = false;
  bool quiet = false;
};

struct Detections {
  std::vector<calib::StereoView> views;  // pairs where either camera found the board
  std::size_t pairs = 0, left = 0, right = 0, both = 0;
  cv::Size size;
  bool stopped = false;
};

Detections detect_all(io::RawStereoInput& input, const calib::BoardSpec& board, const CalibrateArgs& args) {
  Detections d;
  const auto start = std::chrono::steady_clock::now();
  auto last_log = start;
  while (auto pair = input.next()) {
    if (app::stop_requested()) {
      d.stopped = true;
      break;
    }
    ++d.pairs;
    d.size = pair->left.size();
    if (pair->index % static_cast<std::size_t>(args.every) != 0) continue;
    calib::StereoView v;
    v.frame = static_cast<int>(pair->index);
    tbb::parallel_invoke([&] { v.left = calib::detect_board(pair->left, board); },
                         [&] { v.right = calib::detect_board(pair->right, board); });
    d.left += !v.left.ids.empty();
    d.right += !v.right.ids.empty();
    d.both += !v.left.ids.empty() && !v.right.ids.empty();
    if (!v.left.ids.empty() || !v.right.ids.empty()) d.views.push_back(std::move(v));
    const auto now = std::chrono::steady_clock::now();
    if (!args.quiet && now - last_log > std::chrono::seconds(2)) {
      last_log = now;
      spdlog::info("calibrate: {}/{} pairs, board in {} left, {} right, ETA {:.0f} s", d.pairs, input.size(), d.left,
                   d.right, eta_seconds(start, d.pairs, std::max(input.size(), d.pairs)));
    }
  }
  if (d.pairs == 0) throw InputError(input.name(), "no image pairs");
  return d;
}

// A folder that holds sensor.yaml files already (a render, or a vendor's calibration): the result
// is compared with them in the report.
std::optional<geometry::RawStereoRig> sensor_yaml_rig(const fs::path& folder) {
  if (folder.empty()) return std::nullopt;
  const fs::path mav0 = folder.filename() == "mav0" || !fs::is_directory(folder / "mav0") ? folder : folder / "mav0";
  const fs::path y0 = mav0 / "cam0" / "sensor.yaml", y1 = mav0 / "cam1" / "sensor.yaml";
  if (!fs::exists(y0) || !fs::exists(y1)) return std::nullopt;
  try {
    const auto c0 = io::read_euroc_camera_yaml(y0), c1 = io::read_euroc_camera_yaml(y1);
    return geometry::RawStereoRig{c0.lens(), c1.lens(), c1.T_BS.inverse() * c0.T_BS};
  } catch (const InputError& e) {
    spdlog::warn("calibrate: the folder's sensor.yaml is not compared: {}", e.what());
    return std::nullopt;
  }
}

void write_outputs(const fs::path& out, const calib::StereoCalibrationResult& r, const calib::BoardSpec& board,
                   const calib::CalibrationOptions& options, cv::Size size, const nlohmann::json& report) {
  const geometry::RawStereoRig rig = calib::rig_of(r);
  io::write_camchain_file(out / "calibration.yaml", rig,
                          fmt::format("plslam calibrate: {} lenses, board {}, stereo RMS {:.3f} px.\nThe raw cameras "
                                      "(Kalibr's camchain.yaml layout); p_cam1 = T_cn_cnm1 * p_cam0, metres.\n"
                                      "Use: plslam run --calib calibration.yaml (a video, a camera, or an EuRoC "
                                      "folder), or copy cam0/ and cam1/ into an EuRoC layout's mav0/.",
                                      calib::to_string(options.model), calib::to_string(board), r.stereo_rms_px));
  for (int cam = 0; cam < 2; ++cam) {
    const auto& lens = cam == 0 ? rig.left : rig.right;
    io::EurocCameraSensor s;
    // The body frame is cam0: a rig calibrated without an IMU has nothing else to refer to.
    s.T_BS = cam == 0 ? Eigen::Isometry3d::Identity() : Eigen::Isometry3d(rig.T_right_left.inverse());
    s.width = lens.width;
    s.height = lens.height;
    s.fu = lens.fx;
    s.fv = lens.fy;
    s.cu = lens.cx;
    s.cv = lens.cy;
    s.distortion_model = lens.model;
    s.distortion = lens.coeffs;
    fs::create_directories(out / fmt::format("cam{}", cam));
    io::write_euroc_camera_yaml(out / fmt::format("cam{}", cam) / "sensor.yaml", s,
                                fmt::format("plslam calibrate cam{} (body frame: cam0)", cam));
  }
  io::write_file_atomically(out / "report.json", [&](std::ostream& o) { o << report.dump(2) << "\n"; });
  std::vector<uchar> png;
  cv::imencode(".png", calib::draw_coverage(r, size, options), png);
  io::write_file_atomically(out / "coverage.png", [&](std::ostream& o) {
    o.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

void log_camera(const char* name, const calib::CameraReport& c) {
  const auto& l = c.lens;
  spdlog::info("calibrate: {}: {} fx {:.3f} fy {:.3f} cx {:.3f} cy {:.3f}, coefficients [{:.6g}, {:.6g}, {:.6g}, "
               "{:.6g}]; RMS {:.3f} px over {} views ({} rejected), {:.0f} % of the image's cells, tilt up to {:.0f} deg",
               name, geometry::to_string(l.model), l.fx, l.fy, l.cx, l.cy, l.coeffs[0], l.coeffs[1], l.coeffs[2],
               l.coeffs[3], c.rms_px, c.views.size(), c.rejected.size(), 100 * c.covered_share, c.max_tilt_deg);
}

// The board as a PNG to print at 300 dpi, with a white margin of one square (the detectors need
// a quiet zone around it).
int print_board(const calib::BoardSpec& board, const fs::path& path) {
  constexpr double kDpi = 300;
  const int px_per_square = static_cast<int>(std::lround(board.square_m / 0.0254 * kDpi));
  if (px_per_square < 20) throw InputError("--board", "squares too small to print");
  cv::Mat image;
  cv::copyMakeBorder(calib::draw_board(board, px_per_square), image, px_per_square, px_per_square, px_per_square,
                     px_per_square, cv::BORDER_CONSTANT, cv::Scalar(255));
  std::vector<uchar> png;
  cv::imencode(".png", image, png);
  io::write_file_atomically(path, [&](std::ostream& o) {
    o.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
  spdlog::info("calibrate: wrote {}: {} x {} px; print it at {:.0f} dpi without scaling ({:.0f} x {:.0f} mm), then "
               "measure a square: give that size in --board",
               path.string(), image.cols, image.rows, kDpi, image.cols / kDpi * 25.4, image.rows / kDpi * 25.4);
  return 0;
}

int run_calibrate(const CalibrateArgs& args) {
  const calib::BoardSpec board = calib::parse_board_spec(args.board);
  if (!args.print_board.empty()) return print_board(board, args.print_board);
  if (args.out.empty()) throw InputError("--out", "required: the output folder (or --print-board FILE.png)");
  calib::CalibrationOptions options;
  options.model = calib::parse_calibration_model(args.model);
  options.max_views = args.max_views;
  io::prepare_output_folder(args.out);
  app::install_stop_signals();
  auto input = io::open_raw_stereo_input(args.input);
  if (!args.quiet) {
    spdlog::info("calibrate: {}: {} pairs, board {}, {} lenses", input->name(), input->size(), calib::to_string(board),
                 calib::to_string(options.model));
  }
  const Detections d = detect_all(*input, board, args);
  if (d.stopped) spdlog::warn("calibrate: {} after {} pairs: calibrating from those", app::stop_signal_name(), d.pairs);
  const auto result = calib::calibrate_stereo(d.views, board, d.size, options, input->name());

  nlohmann::json report = calib::calibration_json(result);
  report["input"] = input->name();
  report["board"] = calib::to_string(board);
  report["model"] = calib::to_string(options.model);
  report["image_size"] = {d.size.width, d.size.height};
  report["pairs"] = {{"read", d.pairs}, {"board_left", d.left}, {"board_right", d.right}, {"board_both", d.both}};
  if (const auto known = sensor_yaml_rig(args.input.folder)) {
    report["against_sensor_yaml"] = calib::calibration_error_json(calib::rig_of(result), *known);
  }
  const fs::path out(args.out);
  report["outputs"] = {{"calibration", (out / "calibration.yaml").string()},
                       {"cam0_sensor_yaml", (out / "cam0" / "sensor.yaml").string()},
                       {"cam1_sensor_yaml", (out / "cam1" / "sensor.yaml").string()},
                       {"coverage_png", (out / "coverage.png").string()}};
  write_outputs(out, result, board, options, d.size, report);

  for (const auto& w : result.warnings) spdlog::warn("calibrate: {}", w);
  if (args.json) {
    print_json(report.dump(2) + "\n");
  } else {
    log_camera("cam0", result.left);
    log_camera("cam1", result.right);
    const auto& s = report["stereo"];
    spdlog::info("calibrate: stereo: baseline {:.5f} m, rotation {:.3f} deg, RMS {:.3f} px over {} views in both",
                 s["baseline_m"].get<double>(), s["rotation_deg"].get<double>(), result.stereo_rms_px,
                 result.stereo_views.size());
    if (report.contains("against_sensor_yaml")) {
      const auto& e = report["against_sensor_yaml"];
      spdlog::info("calibrate: against the folder's sensor.yaml: fx {:+.3f} % / {:+.3f} %, cx {:+.2f} / {:+.2f} px, "
                   "baseline {:+.3f} %, rotation {:.4f} deg, lens mapping within {:.2f} / {:.2f} px",
                   e["cam0"]["fx_percent"].get<double>(), e["cam1"]["fx_percent"].get<double>(),
                   e["cam0"]["cx_px"].get<double>(), e["cam1"]["cx_px"].get<double>(),
                   e["baseline_percent"].get<double>(), e["rotation_deg"].get<double>(),
                   e["cam0"]["worst_pixel_difference"].get<double>(), e["cam1"]["worst_pixel_difference"].get<double>());
    }
    spdlog::info("calibrate: wrote {} (plslam run --calib), cam0/ and cam1/sensor.yaml, report.json, coverage.png",
                 (out / "calibration.yaml").string());
  }
  return d.stopped ? app::stop_exit_code() : 0;
}

CommandRegistration register_calibrate_command(
    {"calibrate", "Calibrate a stereo rig from a ChArUco board or chessboard moved in front of it",
     [](CLI::App& sub) -> std::function<int()> {
       auto args = std::make_shared<CalibrateArgs>();
       sub.add_option("folder", args->input.folder, "EuRoC-layout folder of the board (mav0/cam0, mav0/cam1)");
       sub.add_option("--left", args->input.left_dir, "Folder of the left camera's images (with --right)");
       sub.add_option("--right", args->input.right_dir, "Folder of the right camera's images, the same file names");
       sub.add_option("--video", args->input.video,
                      "Video of the board: both images side by side (left | right), or the left camera's with "
                      "--video-right");
       sub.add_option("--video-right", args->input.video_right, "The right camera's video, frame for frame");
       sub.add_option("--board", args->board,
                      "charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT] or chessboard:COLSxROWS:SQUARE_M (squares, "
                      "metres; DICT as OpenCV's, e.g. 5x5_100)")
           ->capture_default_str();
       sub.add_option("--model", args->model, "Lens model: pinhole, radtan (radial-tangential) or equidistant (fisheye)")
           ->capture_default_str();
       sub.add_option("--out", args->out,
                      "Output folder: calibration.yaml, cam0/sensor.yaml, cam1/sensor.yaml, report.json, coverage.png");
       sub.add_option("--print-board", args->print_board,
                      "Write the board (--board) as a PNG to print at 300 dpi, and stop");
       sub.add_option("--every", args->every, "Look for the board in every N-th pair only")
           ->check(CLI::Range(1, 1000))
           ->capture_default_str();
       sub.add_option("--max-views", args->max_views, "Views kept for the solve, chosen for coverage of the image")
           ->check(CLI::Range(6, 1000))
           ->capture_default_str();
       sub.add_flag("--json", args->json, "Print the report as JSON");
       sub.add_flag("--quiet", args->quiet, "No progress lines");
       return [args] { return run_calibrate(*args); };
     }});

}  // namespace
}  // namespace plslam::cli
