// Dataset folders as `plslam info` and `plslam run` open them: a small valid KITTI or EuRoC
// layout in the scratch folder, with one file replaced by the fuzzer's bytes. Opening parses the
// calibration, times and ground truth; the first frame is then loaded.
#include <opencv2/imgcodecs.hpp>

#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/dataset.h"

namespace plslam::fuzz {
namespace {

namespace fs = std::filesystem;

void write_image(const fs::path& p, int width, int height) {
  if (fs::exists(p)) return;
  fs::create_directories(p.parent_path());
  cv::Mat img(height, width, CV_8U);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) img.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>((r * 7 + c * 13) % 251);
  cv::imwrite(p.string(), img);
}

const char* kKittiCalib =
    "P0: 7.0e+02 0 3.2e+02 0 0 7.0e+02 2.4e+02 0 0 0 1 0\n"
    "P1: 7.0e+02 0 3.2e+02 -3.5e+02 0 7.0e+02 2.4e+02 0 0 0 1 0\n"
    "P2: 7.0e+02 0 3.2e+02 4.6e+01 0 7.0e+02 2.4e+02 0 0 0 1 0\n"
    "P3: 7.0e+02 0 3.2e+02 -3.4e+02 0 7.0e+02 2.4e+02 0 0 0 1 0\n";
const char* kKittiTimes = "0.000000e+00\n1.000000e-01\n";
const char* kKittiPoses =
    "1 0 0 0 0 1 0 0 0 0 1 0\n"
    "1 0 0 0 0 1 0 0 0 0 1 1\n";

// sequences/00 with two 64x48 frames and poses/00.txt; `replace` names the fuzzed file.
fs::path kitti_layout(const std::string& replace, const std::string& bytes) {
  const fs::path root = scratch_dir() / "kitti";
  const fs::path seq = root / "sequences" / "00";
  for (const char* cam : {"image_0", "image_1"})
    for (const char* name : {"000000.png", "000001.png"}) write_image(seq / cam / name, 64, 48);
  write_file(seq / "calib.txt", replace == "calib.txt" ? bytes : kKittiCalib);
  write_file(seq / "times.txt", replace == "times.txt" ? bytes : kKittiTimes);
  write_file(root / "poses" / "00.txt", kKittiPoses);
  return seq;
}

const char* kEurocSensor =
    "%YAML:1.0\n"
    "sensor_type: camera\n"
    "T_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, {X}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\n"
    "rate_hz: 20\n"
    "resolution: [64, 48]\n"
    "camera_model: pinhole\n"
    "intrinsics: [45.0, 45.0, 32.0, 24.0]\n"
    "distortion_model: radial-tangential\n"
    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n";
const char* kEurocData = "#timestamp [ns],filename\n1000000000,1000000000.png\n1050000000,1050000000.png\n";
const char* kEurocGt =
    "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n"
    "1000000000,0,0,0,1,0,0,0\n1050000000,0.1,0,0,1,0,0,0\n";

std::string sensor_yaml(const char* x) {
  std::string s = kEurocSensor;
  s.replace(s.find("{X}"), 3, x);
  return s;
}

// mav0 with two 64x48 frames per camera and ground truth; `replace` names the fuzzed file.
fs::path euroc_layout(const std::string& replace, const std::string& bytes) {
  const fs::path mav0 = scratch_dir() / "euroc" / "mav0";
  for (const char* cam : {"cam0", "cam1"})
    for (const char* name : {"1000000000.png", "1050000000.png"}) write_image(mav0 / cam / "data" / name, 64, 48);
  write_file(mav0 / "cam0" / "data.csv", replace == "cam0/data.csv" ? bytes : kEurocData);
  write_file(mav0 / "cam1" / "data.csv", kEurocData);
  write_file(mav0 / "cam0" / "sensor.yaml", replace == "cam0/sensor.yaml" ? bytes : sensor_yaml("0.0"));
  write_file(mav0 / "cam1" / "sensor.yaml", sensor_yaml("0.11"));
  write_file(mav0 / "state_groundtruth_estimate0" / "data.csv", replace == "groundtruth.csv" ? bytes : kEurocGt);
  return mav0;
}

void open_and_load(const fs::path& path) {
  const auto ds = io::open_dataset(path);
  (void)ds->fps();
  (void)ds->ground_truth_length();
  if (ds->size() > 0) (void)ds->load(0);
}

}  // namespace

int fuzz_kitti_calib(const std::uint8_t* data, std::size_t size) {
  const auto seq = kitti_layout("calib.txt", as_string(data, size));
  return expect_only_input_errors("kitti_calib", [&] { open_and_load(seq); });
}

int fuzz_kitti_times(const std::uint8_t* data, std::size_t size) {
  const auto seq = kitti_layout("times.txt", as_string(data, size));
  return expect_only_input_errors("kitti_times", [&] { open_and_load(seq); });
}

int fuzz_euroc_data_csv(const std::uint8_t* data, std::size_t size) {
  const auto mav0 = euroc_layout("cam0/data.csv", as_string(data, size));
  return expect_only_input_errors("euroc_data_csv", [&] { open_and_load(mav0); });
}

int fuzz_euroc_groundtruth(const std::uint8_t* data, std::size_t size) {
  const auto mav0 = euroc_layout("groundtruth.csv", as_string(data, size));
  return expect_only_input_errors("euroc_groundtruth", [&] { open_and_load(mav0); });
}

}  // namespace plslam::fuzz
