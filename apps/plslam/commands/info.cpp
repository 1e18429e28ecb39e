// plslam info <dataset> | --video FILE --calib FILE: what the readers see — format, size, rate,
// rectified calibration, ground truth, and the IMU.
#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "json_stdout.h"
#include "commands/dataset_options.h"
#include "plslam/core/error.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/video_dataset.h"

namespace plslam::cli {
namespace {

struct InfoArgs {
  DatasetArgs dataset;
  std::string video;  // --video FILE
  std::string calib;  // --calib FILE, for --video
  bool json = false;
};

void check_input(const InfoArgs& a) {
  if (a.dataset.path.empty() == a.video.empty()) {
    throw InputError("", a.video.empty() ? "no input: give a dataset folder or --video FILE"
                                         : "give one input only: a dataset folder or --video FILE");
  }
  if (!a.video.empty() && a.calib.empty()) throw InputError("", "--video needs --calib FILE");
  if (a.video.empty() && !a.calib.empty()) {
    throw InputError("", "--calib is for --video (a dataset folder has its own calibration)");
  }
  if (!a.video.empty() && a.dataset.format != "auto") throw InputError("", "--format is for dataset folders");
  check_imu_args(a.dataset);
}

double rotation_deg(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI; }

nlohmann::json imu_json(const io::Dataset& ds) {
  if (!ds.imu()) return nullptr;
  const auto& imu = *ds.imu();
  const auto& s = imu.samples;
  const auto& n = imu.calibration.noise;
  nlohmann::json T = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    T.push_back({imu.T_imu_cam.matrix()(r, 0), imu.T_imu_cam.matrix()(r, 1), imu.T_imu_cam.matrix()(r, 2),
                 imu.T_imu_cam.matrix()(r, 3)});
  }
  return {{"path", ds.imu_path().string()},
          {"samples", s.size()},
          {"rate_hz_nominal", imu.calibration.rate_hz},
          {"rate_hz_measured", io::median_rate_hz(s)},
          {"t_first_s", s.front().t},
          {"t_last_s", s.back().t},
          {"frames_t_first_s", ds.timestamps().front()},
          {"frames_t_last_s", ds.timestamps().back()},
          {"T_imu_cam", T},
          {"rotation_deg", rotation_deg(imu.T_imu_cam)},
          {"translation_m", imu.T_imu_cam.translation().norm()},
          {"noise",
           {{"gyroscope_noise_density", n.gyro_noise_density},
            {"gyroscope_random_walk", n.gyro_random_walk},
            {"accelerometer_noise_density", n.acc_noise_density},
            {"accelerometer_random_walk", n.acc_random_walk}}}};
}

std::string imu_text(const io::Dataset& ds) {
  if (!ds.imu()) return "imu          none\n";
  const auto& imu = *ds.imu();
  const auto& s = imu.samples;
  const auto& n = imu.calibration.noise;
  const double t0 = ds.timestamps().front();
  const Eigen::Vector3d p = imu.T_imu_cam.translation();
  return fmt::format("imu          {} samples, {:.2f} Hz nominal, {:.2f} Hz measured (median)  ({})\n", s.size(),
                     imu.calibration.rate_hz, io::median_rate_hz(s), ds.imu_path().string()) +
         fmt::format("imu span     {:+.3f} s to {:+.3f} s from the first frame (frames to {:+.3f} s)\n",
                     s.front().t - t0, s.back().t - t0, ds.timestamps().back() - t0) +
         fmt::format("imu to cam   T_imu_cam: rotation {:.3f} deg, translation ({:.4f}, {:.4f}, {:.4f}) m, {:.4f} m\n",
                     rotation_deg(imu.T_imu_cam), p.x(), p.y(), p.z(), p.norm()) +
         fmt::format("imu noise    gyro {:.4e} rad/s/sqrt(Hz), walk {:.4e} rad/s^2/sqrt(Hz); "
                     "acc {:.4e} m/s^2/sqrt(Hz), walk {:.4e} m/s^3/sqrt(Hz)\n",
                     n.gyro_noise_density, n.gyro_random_walk, n.acc_noise_density, n.acc_random_walk);
}

nlohmann::json lens_json(const geometry::LensCamera& c) {
  return {{"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy}, {"distortion_coefficients", c.coeffs}};
}

// The raw cameras of an input rectified on reading; null for one that comes rectified.
nlohmann::json raw_rig_json(const io::Dataset& ds) {
  if (!ds.raw_rig()) return nullptr;
  const auto& r = *ds.raw_rig();
  const auto& cov = r.coverage;
  return {{"model", geometry::to_string(r.rig.left.model)},
          {"cam0", lens_json(r.rig.left)},
          {"cam1", lens_json(r.rig.right)},
          {"balance", r.balance},
          {"raw_hfov_deg", cov.raw_hfov_deg},
          {"raw_vfov_deg", cov.raw_vfov_deg},
          {"rectified_hfov_deg", cov.rect_hfov_deg},
          {"rectified_vfov_deg", cov.rect_vfov_deg},
          {"kept_share", cov.kept_share},
          {"blank_share", cov.blank_share}};
}

std::string raw_rig_text(const io::Dataset& ds) {
  if (!ds.raw_rig()) return "raw cameras  none (the input comes rectified)\n";
  const auto& r = *ds.raw_rig();
  const auto& cov = r.coverage;
  std::string out;
  for (const auto* c : {&r.rig.left, &r.rig.right}) {
    out += fmt::format("raw cam{}     {}: fx {:.3f}  fy {:.3f}  cx {:.3f}  cy {:.3f}  coefficients {:.6g}\n",
                       c == &r.rig.left ? 0 : 1, geometry::to_string(c->model), c->fx, c->fy, c->cx, c->cy,
                       fmt::join(c->coeffs, " "));
  }
  return out + fmt::format("field of view raw {:.1f} x {:.1f} deg, rectified {:.1f} x {:.1f} deg (balance {:.2f}): "
                           "{:.1f} % of the raw left image kept, {:.1f} % of the rectified one blank\n",
                           cov.raw_hfov_deg, cov.raw_vfov_deg, cov.rect_hfov_deg, cov.rect_vfov_deg, r.balance,
                           100.0 * cov.kept_share, 100.0 * cov.blank_share);
}

int run_info(const InfoArgs& args) {
  check_input(args);
  const auto ds = args.video.empty() ? io::open_dataset(args.dataset.path, args.dataset.options())
                                     : io::open_video_dataset(args.video, args.calib, args.dataset.options());
  const auto& c = ds->calibration();
  const auto& t = ds->timestamps();
  const double duration = t.back() - t.front();
  if (args.json) {
    nlohmann::json j = {{"format", io::to_string(ds->format())},
                        {"frames", ds->size()},
                        {"width", c.width},
                        {"height", c.height},
                        {"fps", ds->fps()},
                        {"fx", c.fx},
                        {"fy", c.fy},
                        {"cx", c.cx},
                        {"cy", c.cy},
                        {"baseline_m", c.baseline},
                        {"duration_s", duration},
                        {"has_ground_truth", ds->ground_truth().has_value()},
                        {"gt_path_length_m", ds->ground_truth_length()},
                        {"raw_cameras", raw_rig_json(*ds)},
                        {"imu", imu_json(*ds)}};
    print_json(j.dump(2) + "\n");
    return 0;
  }
  std::cout << fmt::format("dataset      {}\n", ds->root().string())
            << fmt::format("format       {}\n", io::to_string(ds->format()))
            << fmt::format("frames       {}\n", ds->size())
            << fmt::format("resolution   {}x{}\n", c.width, c.height)
            << fmt::format("rate         {:.2f} fps\n", ds->fps())
            << fmt::format("duration     {:.2f} s\n", duration)
            << fmt::format("rectified    fx {:.3f}  fy {:.3f}  cx {:.3f}  cy {:.3f}\n", c.fx, c.fy, c.cx, c.cy)
            << fmt::format("baseline     {:.4f} m  (bf {:.3f})\n", c.baseline, c.bf()) << raw_rig_text(*ds);
  if (ds->ground_truth()) {
    std::cout << fmt::format("ground truth {} poses, {:.2f} m path  ({})\n", ds->ground_truth()->size(),
                             ds->ground_truth_length(), ds->ground_truth_path().string());
  } else {
    std::cout << "ground truth none\n";
  }
  std::cout << imu_text(*ds);
  return 0;
}

CommandRegistration register_info_command({"info", "Describe a stereo dataset (format, frames, calibration, ground truth, IMU)",
                         [](CLI::App& sub) {
                           auto args = std::make_shared<InfoArgs>();
                           add_dataset_options(sub, args->dataset, "--max-frames", false);
                           sub.add_option("--video", args->video,
                                          "Side-by-side stereo video instead of a dataset folder (as plslam run)");
                           sub.add_option("--calib", args->calib, "Stereo calibration file, for --video");
                           add_imu_options(sub, args->dataset);
                           sub.add_flag("--json", args->json, "Print a JSON object");
                           return std::function<int()>([args] { return run_info(*args); });
                         }});

}  // namespace
}  // namespace plslam::cli
