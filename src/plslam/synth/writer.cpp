#include "plslam/synth/writer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/core/worker_pool.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/io/video_dataset.h"

namespace plslam::synth {

namespace fs = std::filesystem;

OutputFormat parse_output_format(const std::string& name) {
  if (name == "euroc") return OutputFormat::kEuroc;
  if (name == "kitti") return OutputFormat::kKitti;
  if (name == "video") return OutputFormat::kVideo;
  throw InputError("", "unknown format '" + name + "' (expected euroc, kitti or video)");
}

Eigen::Isometry3d euroc_T_BS_cam0() {
  // Body: x forward, y left, z up (IMU-like). The camera looks along body x, slightly rotated
  // and offset like a real rig, so consumers must really apply T_BS.
  Eigen::Matrix3d R_nominal;
  R_nominal << 0, 0, 1,   // camera z (forward) -> body x
      -1, 0, 0,           // camera x (right)   -> body -y
      0, -1, 0;           // camera y (down)    -> body -z
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-0.015, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix() *
               R_nominal;
  T.translation() = Eigen::Vector3d(0.065, 0.02, -0.01);
  return T;
}

std::int64_t euroc_timestamp_ns(const Sequence& seq, std::size_t i) {
  // Start at 1 s so times stay exactly representable as double seconds.
  return 1'000'000'000LL + std::llround(static_cast<double>(i) * 1e9 / seq.options().preset.fps);
}

namespace {

std::ofstream open_out(const fs::path& p) {
  fs::create_directories(p.parent_path());
  std::ofstream out(p);
  if (!out) throw InputError(p.string(), "cannot open for writing");
  return out;
}

void write_png(const fs::path& p, const cv::Mat& img) {
  if (!cv::imwrite(p.string(), img)) throw InputError(p.string(), "cannot write image");
}

std::string matrix_yaml(const Eigen::Isometry3d& T) {
  const Eigen::Matrix4d M = T.matrix();
  std::string s = "  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      s += fmt::format("{:.17g}", M(r, c));
      if (r < 3 || c < 3) s += ", ";
    }
    if (r < 3) s += "\n         ";
  }
  return s + "]\n";
}

void write_sensor_yaml(const fs::path& p, const Sequence& seq, const Eigen::Isometry3d& T_BS, int cam) {
  const geometry::LensCamera l = seq.lens(cam);
  const bool ideal = seq.options().camera == CameraKind::kPinhole;
  io::EurocCameraSensor s;
  s.T_BS = T_BS;
  s.width = l.width;
  s.height = l.height;
  s.fu = l.fx;
  s.fv = l.fy;
  s.cu = l.cx;
  s.cv = l.cy;
  s.distortion_model = ideal ? geometry::LensModel::kRadialTangential : l.model;
  if (!ideal) s.distortion = l.coeffs;
  s.rate_hz = seq.options().preset.fps;
  io::write_euroc_camera_yaml(p, s, fmt::format("plslam synth cam{} ({})", cam, ideal ? "ideal rectified pinhole"
                                                : fmt::format("{} lens", to_string(seq.options().camera))));
}

void write_imu(const SyntheticImu& imu, const fs::path& dir) {
  {
    auto csv = open_out(dir / "data.csv");
    csv << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
           "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    for (const ImuSample& s : imu.samples()) {
      // The IMU's clock on the images' time base: EuRoC stamps start at 1 s (euroc_timestamp_ns).
      csv << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", 1'000'000'000LL + std::llround(s.t * 1e9),
                         s.gyro.x(), s.gyro.y(), s.gyro.z(), s.acc.x(), s.acc.y(), s.acc.z());
    }
  }
  const ImuNoise n = imu.noise();
  auto out = open_out(dir / "sensor.yaml");
  out << "%YAML:1.0\nsensor_type: imu\ncomment: plslam synth IMU"
      << (imu.options().noise_scale > 0 ? fmt::format(" (EuRoC ADIS16448 noise x {})", imu.options().noise_scale)
                                        : std::string(" (exact samples; the noise values are EuRoC's nominal ones)"))
      << "\n\n# Sensor extrinsics wrt. the body-frame.\nT_BS:\n" << matrix_yaml(Eigen::Isometry3d::Identity())
      << fmt::format("rate_hz: {}\n\n", imu.options().rate_hz)
      << fmt::format("gyroscope_noise_density: {:.9g}     # [ rad / s / sqrt(Hz) ]\n", n.gyro_noise_density)
      << fmt::format("gyroscope_random_walk: {:.9g}       # [ rad / s^2 / sqrt(Hz) ]\n", n.gyro_random_walk)
      << fmt::format("accelerometer_noise_density: {:.9g} # [ m / s^2 / sqrt(Hz) ]\n", n.acc_noise_density)
      << fmt::format("accelerometer_random_walk: {:.9g}   # [ m / s^3 / sqrt(Hz) ]\n", n.acc_random_walk);
}

// EuRoC's state_groundtruth_estimate0 columns: position, orientation (w, x, y, z), velocity and
// the true biases of the IMU (= body) frame.
void write_state_ground_truth(const Sequence& seq, const SyntheticImu& imu, const fs::path& path) {
  auto out = open_out(path);
  out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
         "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
         "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const ImuTrueState s = imu.true_state(seq.time(i));
    const Eigen::Vector3d& p = s.T_wb.translation();
    const Eigen::Quaterniond q(s.T_wb.linear());
    out << fmt::format("{},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},"
                       "{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g}\n",
                       euroc_timestamp_ns(seq, i), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), s.v_wb.x(),
                       s.v_wb.y(), s.v_wb.z(), s.bg.x(), s.bg.y(), s.bg.z(), s.ba.x(), s.ba.y(), s.ba.z());
  }
}

void write_ground_truth_extras(const Sequence& seq, const fs::path& dir, const Eigen::Isometry3d& T_out_world,
                               const std::vector<double>& times, const char* frame_name,
                               const SyntheticImu* imu = nullptr) {
  {
    auto out = open_out(dir / "segments_3d.txt");
    out << "# x1 y1 z1 x2 y2 z2 [m], straight scene edges, frame: " << frame_name << "\n";
    for (const Segment3d& s : seq.scene().edges()) {
      const Eigen::Vector3d a = T_out_world * s.a, b = T_out_world * s.b;
      out << fmt::format("{:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
    }
  }
  {
    auto out = open_out(dir / "points_3d.txt");
    out << "# x y z [m], points on scene surfaces, frame: " << frame_name << "\n";
    for (const Eigen::Vector3d& p : seq.scene().sample_points(4, seq.options().seed)) {
      const Eigen::Vector3d q = T_out_world * p;
      out << fmt::format("{:.9g} {:.9g} {:.9g}\n", q.x(), q.y(), q.z());
    }
  }
  Trajectory left;
  for (std::size_t i = 0; i < seq.size(); ++i) left.push_back({times[i], T_out_world * seq.left_pose(i)});
  io::write_trajectory(dir / "left_camera.tum", left, io::TrajectoryFormat::kTum);
  const auto& o = seq.options();
  nlohmann::json j = {{"scene", to_string(o.scene)}, {"preset", o.preset.name}, {"frames", o.frames},
                      {"seed", o.seed},   {"loop", o.loop},  {"loop_overlap", o.loop_overlap}, {"motion_blur", o.motion_blur},
                      {"fps", o.preset.fps}, {"width", o.preset.width}, {"height", o.preset.height},
                      {"fx", seq.lens(0).fx}, {"fy", seq.lens(0).fy}, {"cx", seq.lens(0).cx}, {"cy", seq.lens(0).cy},
                      {"baseline_m", o.preset.baseline}, {"path_length_m", seq.path().length()},
                      {"speed_mps", seq.path().speed()}, {"frame", frame_name}};
  j["path_seed"] = o.path_seed;
  j["motion"] = to_string(o.motion);
  if (o.scene == SceneKind::kCalibration) j["board"] = calib::to_string(o.board);
  if (o.camera != CameraKind::kPinhole || o.fov_deg != 0) {
    j["camera"] = to_string(o.camera);
    j["fov_deg"] = o.fov_deg;
  }
  if (imu) {
    const auto& io = imu->options();
    const Eigen::Vector3d &bg = imu->initial_gyro_bias(), &ba = imu->initial_acc_bias();
    j["imu"] = {{"rate_hz", io.rate_hz},
                {"noise_scale", io.noise_scale},
                {"time_offset_s", io.time_offset},
                {"samples", imu->samples().size()},
                {"initial_gyro_bias", {bg.x(), bg.y(), bg.z()}},
                {"initial_acc_bias", {ba.x(), ba.y(), ba.z()}}};
  }
  // The scene's world from the ground truth's frame (row-major 4x4): KITTI's ground truth starts
  // at each sequence's first camera, so runs on two paths through one scene (a saved map, then
  // localization) are compared in this common world.
  const Eigen::Matrix4d W = T_out_world.inverse().matrix();
  std::vector<double> rows;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) rows.push_back(W(r, c));
  }
  j["world_from_ground_truth"] = rows;
  open_out(dir / "synth.json") << j.dump(2) << "\n";
}

// False when `cancelled` stopped it before every frame was written. With `in_order` (a video),
// batches of a few chunks per thread are rendered in parallel, kept, and handed to `sink` in frame
// order from the calling thread, so memory holds one batch however long the sequence is;
// otherwise `sink` runs on the rendering threads, in any order.
bool render_all(const Sequence& seq, const Progress& progress, int threads, const Cancelled& cancelled,
                const std::function<void(std::size_t, const StereoImages&)>& sink, bool in_order = false) {
  const std::size_t n = seq.size();
  std::size_t done = 0;
  std::mutex mu;
  std::atomic<bool> stopped{false};
  // Chunks of 8 frames, each with its own renderer (it keeps per-thread scratch images).
  constexpr std::size_t kChunk = 8;
  std::unique_ptr<core::WorkerPool> pool;
  if (threads != 1) pool = std::make_unique<core::WorkerPool>(threads, "plslam-synth");
  const std::size_t per_batch = in_order ? kChunk * 2 * static_cast<std::size_t>(pool ? pool->threads() : 1) : n;
  std::vector<StereoImages> batch;
  for (std::size_t first = 0; first < n; first += per_batch) {
    const std::size_t last = std::min(n, first + per_batch);
    if (in_order) batch.assign(last - first, {});
    auto body = [&](int c) {
      StereoRenderer renderer(seq);
      const std::size_t begin = first + static_cast<std::size_t>(c) * kChunk, end = std::min(last, begin + kChunk);
      for (std::size_t i = begin; i < end; ++i) {
        if (stopped.load() || (cancelled && cancelled())) {
          stopped.store(true);
          return;
        }
        if (in_order) {
          batch[i - first] = renderer.render(i);
        } else {
          sink(i, renderer.render(i));
        }
        std::lock_guard<std::mutex> lock(mu);
        ++done;
        if (progress) progress(done, n);
      }
    };
    const int chunks = static_cast<int>((last - first + kChunk - 1) / kChunk);
    if (pool) {
      pool->run(chunks, body);
    } else {
      for (int c = 0; c < chunks; ++c) body(c);
    }
    if (stopped.load()) return false;
    for (std::size_t k = 0; in_order && k < batch.size(); ++k) sink(first + k, batch[k]);
  }
  return true;
}

// The video layout (writer.h). FFV1 keeps every grey level exactly, so a run on the video sees
// the images a run on the image folders sees.
bool write_video(const Sequence& seq, const fs::path& dir, const Progress& progress, int threads,
                 const Cancelled& cancelled) {
  const auto& pr = seq.options().preset;
  const std::size_t n = seq.size();
  fs::create_directories(dir);
  const fs::path video = dir / kVideoFile;
  io::quiet_ffmpeg_log();
  cv::VideoWriter writer;
  if (!writer.open(video.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), pr.fps,
                   cv::Size(2 * pr.width, pr.height), false)) {
    throw InputError(video.string(), "cannot write an FFV1 video (OpenCV's FFmpeg backend refused it)");
  }
  cv::Mat side_by_side;
  const bool complete = render_all(
      seq, progress, threads, cancelled,
      [&](std::size_t, const StereoImages& im) {
        cv::hconcat(im.left, im.right, side_by_side);
        writer.write(side_by_side);
      },
      true);
  writer.release();
  if (!complete) return false;
  // VideoWriter reports no write errors (a full disk): read the header back. The rate is stored as
  // a fraction, so the ground truth takes the rate a reader gets, and its times match the frames'.
  cv::VideoCapture check(video.string(), cv::CAP_FFMPEG);
  const double frames = check.get(cv::CAP_PROP_FRAME_COUNT), fps = check.get(cv::CAP_PROP_FPS);
  if (!check.isOpened() || frames != static_cast<double>(n) || !(fps > 0)) {
    throw InputError(video.string(), fmt::format("the written video reads back as {} frames at {} Hz, not {} at {}",
                                                 frames, fps, n, pr.fps));
  }
  if (std::abs(fps - pr.fps) > 1e-9 * pr.fps) spdlog::info("synth: {} stores the rate as {:.9g} Hz", video.string(), fps);
  io::write_calibration_file(dir / kVideoCalibrationFile, seq.calibration());
  std::vector<double> times;
  Trajectory left;
  for (std::size_t i = 0; i < n; ++i) {
    times.push_back(static_cast<double>(i) / fps);
    left.push_back({times.back(), seq.left_pose(i)});
  }
  io::write_trajectory(io::video_ground_truth_path(video), left, io::TrajectoryFormat::kTum);
  write_ground_truth_extras(seq, dir / "synth", Eigen::Isometry3d::Identity(), times, "scene world");
  return true;
}

}  // namespace

std::uint64_t imu_seed(const SequenceOptions& o) { return o.seed * 0x2545F4914F6CDD1DULL ^ (o.path_seed << 17) ^ 0x1BB; }

bool write_sequence(const Sequence& seq, const fs::path& dir, OutputFormat format, const Progress& progress,
                    int threads, const Cancelled& cancelled, const ImuSynthOptions& imu_options) {
  // KITTI and video hold a rectified pair's calibration only: refuse a raw rig before rendering.
  if (format != OutputFormat::kEuroc) (void)seq.calibration();
  if (format == OutputFormat::kVideo) return write_video(seq, dir, progress, threads, cancelled);
  const std::size_t n = seq.size();
  if (format == OutputFormat::kEuroc) {
    const fs::path mav = dir / "mav0";
    const Eigen::Isometry3d T_BS0 = euroc_T_BS_cam0();
    const Eigen::Isometry3d T_c0c1 = seq.T_left_right();
    std::vector<double> times;
    for (int cam = 0; cam < 2; ++cam) {
      const fs::path cdir = mav / fmt::format("cam{}", cam);
      fs::create_directories(cdir / "data");
      auto csv = open_out(cdir / "data.csv");
      csv << "#timestamp [ns],filename\n";
      for (std::size_t i = 0; i < n; ++i) csv << fmt::format("{0},{0}.png\n", euroc_timestamp_ns(seq, i));
      write_sensor_yaml(cdir / "sensor.yaml", seq, cam == 0 ? T_BS0 : T_BS0 * T_c0c1, cam);
    }
    for (std::size_t i = 0; i < n; ++i) times.push_back(static_cast<double>(euroc_timestamp_ns(seq, i)) * 1e-9);
    // Still views (the calibration scene) have no motion to measure: no IMU, no body trajectory.
    std::optional<SyntheticImu> imu;
    if (seq.has_path()) {
      imu.emplace(seq, T_BS0, imu_options, imu_seed(seq.options()));  // IMU = body frame
      write_imu(*imu, mav / "imu0");
      write_state_ground_truth(seq, *imu, mav / "state_groundtruth_estimate0" / "data.csv");
    }
    const bool complete = render_all(seq, progress, threads, cancelled, [&](std::size_t i, const StereoImages& im) {
      const std::string name = fmt::format("{}.png", euroc_timestamp_ns(seq, i));
      write_png(mav / "cam0" / "data" / name, im.left);
      write_png(mav / "cam1" / "data" / name, im.right);
    });
    if (!complete) return false;
    // Last, so that synth/synth.json marks a complete sequence.
    write_ground_truth_extras(seq, mav / "synth", Eigen::Isometry3d::Identity(), times, "euroc world (z up)",
                              imu ? &*imu : nullptr);
    return true;
  }
  const fs::path sdir = dir / "sequences" / "00";
  fs::create_directories(sdir / "image_0");
  fs::create_directories(sdir / "image_1");
  const StereoCalibration pr = seq.calibration();
  {
    auto calib = open_out(sdir / "calib.txt");
    for (int cam = 0; cam < 2; ++cam) {
      const double tx = cam == 0 ? 0.0 : -pr.fx * pr.baseline;
      calib << fmt::format("P{}: {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}\n",
                           cam, pr.fx, 0.0, pr.cx, tx, 0.0, pr.fy, pr.cy, 0.0, 0.0, 0.0, 1.0, 0.0);
    }
  }
  std::vector<double> times;
  {
    auto out = open_out(sdir / "times.txt");
    for (std::size_t i = 0; i < n; ++i) {
      times.push_back(seq.time(i));
      out << fmt::format("{:.6e}\n", seq.time(i));
    }
  }
  const Eigen::Isometry3d T_0w = seq.left_pose(0).inverse();
  Trajectory poses;
  for (std::size_t i = 0; i < n; ++i) poses.push_back({times[i], T_0w * seq.left_pose(i)});
  poses[0].T = Eigen::Isometry3d::Identity();  // exactly, not up to rounding
  io::write_trajectory(dir / "poses" / "00.txt", poses, io::TrajectoryFormat::kKitti);
  const bool complete = render_all(seq, progress, threads, cancelled, [&](std::size_t i, const StereoImages& im) {
    write_png(sdir / "image_0" / fmt::format("{:06d}.png", i), im.left);
    write_png(sdir / "image_1" / fmt::format("{:06d}.png", i), im.right);
  });
  if (!complete) return false;
  write_ground_truth_extras(seq, sdir / "synth", T_0w, times, "kitti first left camera");
  return true;
}

}  // namespace plslam::synth
