#pragma once
// Tiny datasets written into a temporary folder, in the real KITTI and EuRoC layouts, so every
// bad-input case can be produced by editing one file.
#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>

namespace plslam::test {

inline cv::Mat noise_image(int w, int h, int seed) {
  cv::Mat img(h, w, CV_8UC1);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  return img;
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// <root>/sequences/00 with `frames` pairs, times.txt and poses/00.txt. Returns the sequence dir.
inline std::filesystem::path make_kitti(const std::filesystem::path& root, int frames = 3, int w = 64,
                                        int h = 48) {
  const auto seq = root / "sequences" / "00";
  std::filesystem::create_directories(seq / "image_0");
  std::filesystem::create_directories(seq / "image_1");
  std::string times, poses;
  for (int i = 0; i < frames; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    cv::imwrite((seq / "image_0" / name).string(), noise_image(w, h, i));
    cv::imwrite((seq / "image_1" / name).string(), noise_image(w, h, 100 + i));
    times += std::to_string(0.1 * i) + "\n";
    poses += "1 0 0 0 0 1 0 0 0 0 1 " + std::to_string(1.0 * i) + "\n";
  }
  write_file(seq / "calib.txt",
             "P0: 500 0 32 0 0 500 24 0 0 0 1 0\n"
             "P1: 500 0 32 -250 0 500 24 0 0 0 1 0\n"
             "P2: 500 0 32 40 0 500 24 0 0 0 1 0\n"
             "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  write_file(seq / "times.txt", times);
  write_file(root / "poses" / "00.txt", poses);
  return seq;
}

inline std::string euroc_sensor_yaml(double tx, const std::string& nan_or_fx = "100.0") {
  return "%YAML:1.0\n"
         "sensor_type: camera\n"
         "T_BS:\n  cols: 4\n  rows: 4\n"
         "  data: [1.0, 0.0, 0.0, " + std::to_string(tx) + ",\n"
         "         0.0, 1.0, 0.0, 0.0,\n"
         "         0.0, 0.0, 1.0, 0.0,\n"
         "         0.0, 0.0, 0.0, 1.0]\n"
         "rate_hz: 20\n"
         "resolution: [64, 48]\n"
         "camera_model: pinhole\n"
         "intrinsics: [" + nan_or_fx + ", 100.0, 32.0, 24.0]\n"
         "distortion_model: radial-tangential\n"
         "distortion_coefficients: [-0.1, 0.01, 0.0, 0.0]\n";
}

// <root>/mav0 with `frames` pairs 50 ms apart and body-frame ground truth. Returns root.
inline std::filesystem::path make_euroc(const std::filesystem::path& root, int frames = 3) {
  const auto mav0 = root / "mav0";
  std::string csv = "#timestamp [ns],filename\n";
  std::string gt = "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n";
  for (int i = 0; i < frames; ++i) {
    const std::string ns = std::to_string(1403715273000000000LL + 50000000LL * i);
    for (int cam = 0; cam < 2; ++cam) {
      const auto dir = mav0 / ("cam" + std::to_string(cam)) / "data";
      std::filesystem::create_directories(dir);
      cv::imwrite((dir / (ns + ".png")).string(), noise_image(64, 48, 10 * i + cam));
    }
    csv += ns + "," + ns + ".png\n";
    gt += ns + "," + std::to_string(0.01 * i) + ",0,0,1,0,0,0\n";
  }
  write_file(mav0 / "cam0" / "data.csv", csv);
  write_file(mav0 / "cam1" / "data.csv", csv);
  write_file(mav0 / "cam0" / "sensor.yaml", euroc_sensor_yaml(0.0));
  write_file(mav0 / "cam1" / "sensor.yaml", euroc_sensor_yaml(0.11));
  write_file(mav0 / "state_groundtruth_estimate0" / "data.csv", gt);
  return root;
}

// An IMU sensor.yaml in EuRoC's imu0 layout (its ADIS16448 noise values), the IMU `tx` metres
// along the body's x axis.
inline std::string imu_sensor_yaml(double tx = 0.0) {
  return "%YAML:1.0\n"
         "sensor_type: imu\n"
         "T_BS:\n  cols: 4\n  rows: 4\n"
         "  data: [1.0, 0.0, 0.0, " + std::to_string(tx) + ",\n"
         "         0.0, 1.0, 0.0, 0.0,\n"
         "         0.0, 0.0, 1.0, 0.0,\n"
         "         0.0, 0.0, 0.0, 1.0]\n"
         "rate_hz: 200\n"
         "gyroscope_noise_density: 1.6968e-04\n"
         "gyroscope_random_walk: 1.9393e-05\n"
         "accelerometer_noise_density: 2.0000e-3\n"
         "accelerometer_random_walk: 3.0000e-3\n";
}

// IMU samples in EuRoC's imu0/data.csv layout from `first_ns` to `last_ns` (inclusive) every
// `period_ns`: gyro (0.01, 0.02, 0.03) rad/s, acc (0.1, 0.2, 9.81) m/s^2.
inline std::string imu_csv(long long first_ns, long long last_ns, long long period_ns = 5'000'000) {
  std::string s = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                  "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  for (long long ns = first_ns; ns <= last_ns; ns += period_ns) {
    s += std::to_string(ns) + ",0.01,0.02,0.03,0.1,0.2,9.81\n";
  }
  return s;
}

// mav0/imu0 for make_euroc's frames (the first at 1403715273000000000 ns, 50 ms apart), 200 Hz
// from `before_s` seconds before the first frame to `after_s` after the last.
inline void add_euroc_imu(const std::filesystem::path& root, int frames = 3, double before_s = 1.0,
                          double after_s = 1.0) {
  const long long first = 1403715273000000000LL, last = first + 50000000LL * (frames - 1);
  write_file(root / "mav0" / "imu0" / "data.csv",
             imu_csv(first - static_cast<long long>(before_s * 1e9), last + static_cast<long long>(after_s * 1e9)));
  write_file(root / "mav0" / "imu0" / "sensor.yaml", imu_sensor_yaml(0.05));
}

}  // namespace plslam::test
