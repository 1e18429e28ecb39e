// Inertial input (issue 52): the IMU sample file and sensor.yaml parsers, EuRoC's mav0/imu0, a
// video's --imu/--imu-calib, what `plslam info` reports, and a one-line error naming the file for
// every bad input.
#include <cmath>
#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "io/fake_datasets.h"
#include "plslam/core/error.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/dataset.h"
#include "plslam/io/euroc_sensor.h"
#include "plslam/io/imu_csv.h"
#include "plslam/io/imu_input.h"
#include "plslam/io/imu_sensor.h"
#include "plslam/io/video_dataset.h"
#include "support/test_support.h"

namespace plslam::io {
namespace imu_input_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

constexpr long long kFirstFrameNs = 1403715273000000000LL;  // make_euroc's first frame

// The InputError of `open`; fails the test when `open` succeeds or the message spans lines.
std::string input_error(const std::function<void()>& open) {
  try {
    open();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

// fmt, not operator+: GCC 12 warns falsely (-Wrestrict) on the inlined concatenation.
std::string q(const fs::path& p) { return fmt::format("\"{}\"", p.string()); }

// ---- The sample file and sensor.yaml ----

TEST(ImuFiles, ReadsTheEurocLayoutWithCommentsBlankLinesCrlfAndColumnNames) {
  test::TempDir tmp;
  const auto path = tmp.path() / "imu.csv";
  test::write_file(path,
                   "timestamp,gx,gy,gz,ax,ay,az\r\n"
                   "# a comment\r\n"
                   "\r\n"
                   "1403715273262142976,-0.0021,0.0175,0.0775,9.0875,0.1308,-3.6938\r\n"
                   "1403715273267142912, -0.0014 ,0.0195,0.0782,9.0793,0.1226,-3.6938\r\n"
                   "1403715273272143104,-1e-3,0,0,0,0,-9.81\r\n");
  const auto s = read_imu_csv(path);
  ASSERT_EQ(s.size(), 3u);
  // The conversion the EuRoC reader applies to image timestamps, so that equal stamps stay equal.
  EXPECT_EQ(s[0].t, static_cast<double>(1403715273262142976LL) * 1e-9);
  EXPECT_EQ(s[1].gyro.x(), -0.0014);
  EXPECT_EQ(s[0].acc, Eigen::Vector3d(9.0875, 0.1308, -3.6938));
  EXPECT_EQ(s[2].gyro, Eigen::Vector3d(-1e-3, 0, 0));
  EXPECT_NEAR(median_rate_hz(s), 200.0, 0.05);
}

TEST(ImuFiles, ALastLineCutShortWithoutItsLineEndIsLeftOut) {
  test::TempDir tmp;
  const auto path = tmp.path() / "imu.csv";
  const std::string three = test::imu_csv(0, 10'000'000);
  test::write_file(path, three + "15000000,0.01,0.0");
  EXPECT_EQ(read_imu_csv(path).size(), 3u);
  // A whole last line without its line end is a sample.
  test::write_file(path, three + "15000000,0.01,0.02,0.03,0.1,0.2,9.81");
  EXPECT_EQ(read_imu_csv(path).size(), 4u);
  // Cut short and ended: not a recording stopped mid-line, but a broken line.
  const auto e = input_error([&] {
    test::write_file(path, three + "15000000,0.01,0.0\n");
    (void)read_imu_csv(path);
  });
  EXPECT_NE(e.find(path.string() + ": line 5: 3 columns, expected 7"), std::string::npos) << e;
}

TEST(ImuFiles, AMissingFileOrAFolderIsNamed) {
  test::TempDir tmp;
  EXPECT_EQ(input_error([&] { (void)read_imu_csv(tmp.path() / "none.csv"); }),
            (tmp.path() / "none.csv").string() + ": file not found");
  EXPECT_EQ(input_error([&] { (void)read_imu_csv(tmp.path()); }),
            tmp.path().string() + ": is a folder, expected a file");
}

TEST(ImuFiles, ReadsEurocsImu0SensorYaml) {
  test::TempDir tmp;
  const auto path = tmp.path() / "sensor.yaml";
  test::write_file(path, test::imu_sensor_yaml(0.25));
  const auto c = read_imu_sensor_yaml(path);
  EXPECT_EQ(c.rate_hz, 200.0);
  EXPECT_EQ(c.T_BS.translation(), Eigen::Vector3d(0.25, 0, 0));
  EXPECT_TRUE(c.T_BS.linear().isIdentity(0));
  EXPECT_EQ(c.noise.gyro_noise_density, kEurocAdis16448Noise.gyro_noise_density);
  EXPECT_EQ(c.noise.gyro_random_walk, kEurocAdis16448Noise.gyro_random_walk);
  EXPECT_EQ(c.noise.acc_noise_density, kEurocAdis16448Noise.acc_noise_density);
  EXPECT_EQ(c.noise.acc_random_walk, kEurocAdis16448Noise.acc_random_walk);
}

// ---- Bad files: one line naming the file (and the line), for each kind of fault ----

struct BadFile {
  std::string name;
  std::string file;  // data.csv (read_imu_csv) or sensor.yaml (read_imu_sensor_yaml)
  std::string text;
  std::string problem;  // what follows "<file>: "
};

void PrintTo(const BadFile& c, std::ostream* os) { *os << c.name; }

class ImuFileBadInput : public ::testing::TestWithParam<BadFile> {};

TEST_P(ImuFileBadInput, OneLineErrorNamingTheFile) {
  test::TempDir tmp;
  const auto path = tmp.path() / GetParam().file;
  test::write_file(path, GetParam().text);
  const auto e = input_error([&] {
    if (GetParam().file == "data.csv") {
      (void)read_imu_csv(path);
    } else {
      (void)read_imu_sensor_yaml(path);
    }
  });
  EXPECT_EQ(e.rfind(path.string() + ": ", 0), 0u) << e;
  EXPECT_NE(e.find(GetParam().problem), std::string::npos) << e;
}

// A sample line at `ns`; every file's line 1 is kHeader.
std::string ok(long long ns) { return std::to_string(ns) + ",0.01,0.02,0.03,0.1,0.2,9.81\n"; }
const std::string kHeader = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";

BadFile csv(const std::string& name, const std::string& text, const std::string& problem) {
  return {name, "data.csv", text, problem};
}

// A valid sensor.yaml with `from` replaced by `to`.
BadFile yaml(const std::string& name, const std::string& from, const std::string& to, const std::string& problem) {
  std::string text = test::imu_sensor_yaml();
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error(name + ": no '" + from + "' to replace");
  return {name, "sensor.yaml", text.replace(at, from.size(), to), problem};
}

const BadFile kBadFiles[] = {
    csv("csv_not_increasing", kHeader + ok(10'000'000) + ok(15'000'000) + ok(12'000'000),
        "line 4: timestamp 12000000 is before 15000000 on line 3: timestamps must increase"),
    csv("csv_duplicate", kHeader + ok(10'000'000) + ok(15'000'000) + ok(15'000'000),
        "line 4: duplicate timestamp 15000000 (also on line 3)"),
    // 5 ms periods, then 30 ms: over 5 median periods (25 ms).
    csv("csv_gap", kHeader + ok(0) + ok(5'000'000) + ok(10'000'000) + ok(15'000'000) + ok(45'000'000) + ok(50'000'000),
        "line 6: a gap of 30.000 ms after the sample on line 5, over 5 median sample periods (5.000 ms)"),
    csv("csv_nan", kHeader + ok(0) + "5000000,0.01,nan,0.03,0.1,0.2,9.81\n", "line 3: non-finite value 'nan'"),
    csv("csv_inf", kHeader + ok(0) + "5000000,0.01,0.02,0.03,0.1,0.2,-inf\n", "line 3: non-finite value '-inf'"),
    csv("csv_not_a_number", kHeader + ok(0) + "5000000,0.01,0.02,0.03,x,0.2,9.81\n", "line 3: 'x' is not a number"),
    csv("csv_empty_field", kHeader + ok(0) + "5000000,0.01,,0.03,0.1,0.2,9.81\n", "line 3: '' is not a number"),
    csv("csv_too_few_columns", kHeader + ok(0) + "5000000,0.01,0.02,0.03,0.1,0.2\n",
        "line 3: 6 columns, expected 7 (timestamp [ns], gyro x y z, acc x y z)"),
    csv("csv_too_many_columns", kHeader + ok(0) + "5000000,0.01,0.02,0.03,0.1,0.2,9.81,1\n",
        "line 3: 8 columns, expected 7"),
    csv("csv_whitespace_separated", kHeader + "0 0.01 0.02 0.03 0.1 0.2 9.81\n", "line 2: 1 columns, expected 7"),
    csv("csv_fractional_timestamp", kHeader + ok(0) + "5000000.5,0.01,0.02,0.03,0.1,0.2,9.81\n",
        "line 3: bad timestamp '5000000.5' (expected whole nanoseconds)"),
    csv("csv_timestamp_overflow", kHeader + "99999999999999999999,0.01,0.02,0.03,0.1,0.2,9.81\n",
        "line 2: bad timestamp '99999999999999999999'"),
    csv("csv_one_sample", kHeader + ok(0), "1 IMU sample, at least 2 are needed"),
    csv("csv_header_only", kHeader, "0 IMU samples, at least 2 are needed"),
    yaml("yaml_rate_zero", "rate_hz: 200", "rate_hz: 0", "'rate_hz' must be positive, got 0"),
    yaml("yaml_rate_negative", "rate_hz: 200", "rate_hz: -200", "'rate_hz' must be positive, got -200"),
    yaml("yaml_rate_missing", "rate_hz: 200\n", "", "missing 'rate_hz'"),
    yaml("yaml_rate_not_a_number", "rate_hz: 200", "rate_hz: fast", "'rate_hz' is not a number"),
    yaml("yaml_rate_a_list", "rate_hz: 200", "rate_hz: [200]", "'rate_hz' is not a number"),
    yaml("yaml_gyro_noise_zero", "gyroscope_noise_density: 1.6968e-04", "gyroscope_noise_density: 0",
         "'gyroscope_noise_density' must be positive, got 0"),
    yaml("yaml_gyro_walk_nan", "gyroscope_random_walk: 1.9393e-05", "gyroscope_random_walk: .nan",
         "'gyroscope_random_walk' must be finite, got nan"),
    yaml("yaml_acc_noise_inf", "accelerometer_noise_density: 2.0000e-3", "accelerometer_noise_density: .inf",
         "'accelerometer_noise_density' must be finite, got inf"),
    yaml("yaml_acc_walk_negative", "accelerometer_random_walk: 3.0000e-3", "accelerometer_random_walk: -3e-3",
         "'accelerometer_random_walk' must be positive, got -0.003"),
    yaml("yaml_acc_walk_missing", "accelerometer_random_walk: 3.0000e-3\n", "", "missing 'accelerometer_random_walk'"),
    yaml("yaml_T_BS_not_rigid", "data: [1.0, 0.0, 0.0,", "data: [2.0, 0.0, 0.0,", "T_BS is not a rigid transform"),
    yaml("yaml_T_BS_short", "         0.0, 0.0, 0.0, 1.0]", "         0.0, 0.0, 0.0]",
         "'T_BS.data' needs 16 numbers, found 15"),
    yaml("yaml_of_a_camera", "sensor_type: imu", "sensor_type: camera", "sensor_type is not 'imu'"),
    // Line 10 opens the list; the parser notices on the next line that it is not closed.
    yaml("yaml_malformed", "rate_hz: 200", "rate_hz: [200",
         "malformed YAML at line 11: end of sequence flow not found"),
};

INSTANTIATE_TEST_SUITE_P(Cases, ImuFileBadInput, ::testing::ValuesIn(kBadFiles),
                         [](const auto& info) { return info.param.name; });

// ---- EuRoC's mav0/imu0 ----

// make_euroc's right camera turned 1 degree about the baseline (x): the rectification then turns
// each camera half of it (a turn about y would leave the left camera as it is).
std::string turned_cam1_yaml() {
  std::string y = test::euroc_sensor_yaml(0.11);
  const double a = M_PI / 180, c = std::cos(a), s = std::sin(a);
  const auto edit = [&](const std::string& from, const std::string& to) { y.replace(y.find(from), from.size(), to); };
  edit("0.0, 1.0, 0.0, 0.0,", fmt::format("0.0, {:.15f}, {:.15f}, 0.0,", c, -s));
  edit("0.0, 0.0, 1.0, 0.0,", fmt::format("0.0, {:.15f}, {:.15f}, 0.0,", s, c));
  return y;
}

TEST(EurocReader, Imu0IsCutToTheFramesAndPlacesTheRectifiedCameraInTheImuFrame) {
  test::TempDir tmp;
  const auto root = test::make_euroc(tmp.path(), 3);
  test::write_file(root / "mav0" / "cam1" / "sensor.yaml", turned_cam1_yaml());
  // Samples half a period off the frames' stamps, so that none lies on the kept span's ends.
  test::add_euroc_imu(root, 3, 2.0025, 2.0);
  const auto ds = open_dataset(root);
  ASSERT_TRUE(ds->imu());
  EXPECT_EQ(ds->imu_path(), root / "mav0" / "imu0" / "data.csv");
  const auto& imu = *ds->imu();
  // Frames 0, 0.05 and 0.1 s after kFirstFrameNs; samples every 5 ms within 0.5 s of them.
  const double t0 = ds->timestamps().front(), t1 = ds->timestamps().back();
  EXPECT_EQ(t0, static_cast<double>(kFirstFrameNs) * 1e-9);
  ASSERT_EQ(imu.samples.size(), 220u);  // (0.5 + 0.1 + 0.5) s at 200 Hz
  EXPECT_NEAR(imu.samples.front().t, t0 - 0.4975, 1e-6);
  EXPECT_NEAR(imu.samples.back().t, t1 + 0.4975, 1e-6);
  EXPECT_EQ(imu.samples[100].acc, Eigen::Vector3d(0.1, 0.2, 9.81));
  EXPECT_EQ(imu.calibration.rate_hz, 200.0);
  EXPECT_EQ(imu.calibration.noise.acc_random_walk, 3e-3);
  // p_imu = T_BS_imu^-1 * T_BS_cam0 * R_rect^T * p_rect: cam0 sits at the body's origin and the IMU
  // 0.05 m along its x axis.
  Eigen::Isometry3d T_imu_body = Eigen::Isometry3d::Identity();
  T_imu_body.translation() = Eigen::Vector3d(-0.05, 0, 0);
  const Eigen::Vector3d p_rect(0.3, -0.2, 2.0);
  const Eigen::Vector3d expected = T_imu_body * (ds->rectification_rotation().transpose() * p_rect);
  EXPECT_LT((imu.T_imu_cam * p_rect - expected).norm(), 1e-12);
  // The rectification turns the left camera by half the rig's 1 degree: leaving it out would show
  // above.
  EXPECT_NEAR(Eigen::AngleAxisd(ds->rectification_rotation()).angle(), 0.5 * M_PI / 180, 1e-6);

  // --start/--max-frames move the kept span with the frames.
  DatasetOptions o;
  o.start = 2;
  const auto last = open_dataset(root, o);
  ASSERT_TRUE(last->imu());
  EXPECT_EQ(last->imu()->samples.size(), 200u);
  EXPECT_NEAR(last->imu()->samples.front().t, last->timestamps().front() - 0.4975, 1e-6);
}

TEST(EurocReader, WithoutImu0ThereIsNoImu) {
  test::TempDir tmp;
  EXPECT_FALSE(open_dataset(test::make_euroc(tmp.path() / "e", 2))->imu());
  EXPECT_FALSE(open_dataset(test::make_kitti(tmp.path() / "k", 2))->imu());
}

TEST(EurocReader, ABrokenOrShortImu0IsRefusedNamingItsFile) {
  test::TempDir tmp;
  int n = 0;
  // A fresh sequence with 3 frames and an IMU from 1 s before to 1 s after them, edited by `edit`.
  const auto refused = [&](const std::function<void(const fs::path& imu0)>& edit) {
    const auto root = test::make_euroc(tmp.path() / std::to_string(n++), 3);
    test::add_euroc_imu(root, 3);
    edit(root / "mav0" / "imu0");
    return input_error([&] { (void)open_dataset(root); });
  };
  std::string e = refused([](const fs::path& d) {
    test::write_file(d / "data.csv", test::imu_csv(kFirstFrameNs + 5'000'000, kFirstFrameNs + 2'000'000'000LL));
  });
  EXPECT_NE(e.find("imu0/data.csv: the IMU samples from 1403715273.005000 s to 1403715275.000000 s do not cover the "
                   "frames from 1403715273.000000 s to 1403715273.100000 s"),
            std::string::npos)
      << e;
  e = refused([](const fs::path& d) {
    test::write_file(d / "data.csv", test::imu_csv(kFirstFrameNs - 1'000'000'000LL, kFirstFrameNs + 95'000'000));
  });
  EXPECT_NE(e.find("imu0/data.csv: the IMU samples from 1403715272.000000 s to 1403715273.095000 s do not cover"),
            std::string::npos)
      << e;
  e = refused([](const fs::path& d) {
    test::write_file(d / "data.csv", test::imu_csv(kFirstFrameNs, kFirstFrameNs + 100'000'000) +
                                         std::to_string(kFirstFrameNs + 100'000'000) + ",0,0,0,0,0,0\n");
  });
  EXPECT_NE(e.find("imu0/data.csv: line 23: duplicate timestamp"), std::string::npos) << e;
  e = refused([](const fs::path& d) { fs::remove(d / "sensor.yaml"); });
  EXPECT_NE(e.find("imu0/sensor.yaml: file not found"), std::string::npos) << e;
  e = refused([](const fs::path& d) { test::write_file(d / "sensor.yaml", test::euroc_sensor_yaml(0.0)); });
  EXPECT_NE(e.find("imu0/sensor.yaml: sensor_type is not 'imu'"), std::string::npos) << e;
  e = refused([](const fs::path& d) {
    fs::remove_all(d);
    test::write_file(d, "not a folder");
  });
  EXPECT_NE(e.find("imu0: is a file, expected the IMU's folder"), std::string::npos) << e;
}

// ---- Video input with --imu ----

constexpr int kW = 64, kH = 48;

struct ImuVideo {
  fs::path video, calib, csv, yaml;
};

// 4 side-by-side FFV1 frames of noise at 20 Hz with their calibration, and an IMU at 100 Hz from
// 1.005 s before the first frame to 1.005 s after the last, in ns on the video's clock (half a
// period off the frames, so that no sample lies on the kept span's ends).
ImuVideo make_imu_video(const fs::path& dir) {
  quiet_ffmpeg_log();
  ImuVideo v{dir / "stereo.mkv", dir / "calibration.yaml", dir / "imu.csv", dir / "imu.yaml"};
  fs::create_directories(dir);
  cv::VideoWriter writer(v.video.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 20.0,
                         cv::Size(2 * kW, kH), false);
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < 4; ++i) {
    cv::Mat sbs;
    cv::hconcat(test::noise_image(kW, kH, 2 * i), test::noise_image(kW, kH, 2 * i + 1), sbs);
    writer.write(sbs);
  }
  writer.release();
  StereoCalibration c;
  c.width = kW;
  c.height = kH;
  c.fx = c.fy = 100;
  c.cx = 32;
  c.cy = 24;
  c.baseline = 0.1;
  write_calibration_file(v.calib, c);
  test::write_file(v.csv, test::imu_csv(-1'005'000'000LL, 1'155'000'000LL, 10'000'000));
  test::write_file(v.yaml, test::imu_sensor_yaml(0.05));
  return v;
}

TEST(VideoDataset, ImuSamplesAreOnTheVideosClockAndItsBodyIsTheLeftCamera) {
  test::TempDir tmp;
  const auto v = make_imu_video(tmp.path());
  DatasetOptions o;
  EXPECT_FALSE(open_video_dataset(v.video, v.calib, o)->imu());
  o.imu_csv = v.csv;
  o.imu_calib = v.yaml;
  o.start = 1;
  const auto ds = open_video_dataset(v.video, v.calib, o);
  ASSERT_TRUE(ds->imu());
  EXPECT_EQ(ds->imu_path(), v.csv);
  const auto& s = ds->imu()->samples;
  // Frames 1..3 at 0.05..0.15 s: samples from -0.445 to 0.645 s.
  ASSERT_EQ(s.size(), 110u);
  EXPECT_NEAR(s.front().t, -0.445, 1e-9);
  EXPECT_NEAR(s.back().t, 0.645, 1e-9);
  // T_BS places the IMU 0.05 m along the camera's x axis: the camera is at -0.05 m in the IMU's frame.
  EXPECT_LT((ds->imu()->T_imu_cam.translation() - Eigen::Vector3d(-0.05, 0, 0)).norm(), 1e-12);
  EXPECT_TRUE(ds->imu()->T_imu_cam.linear().isIdentity(1e-12));

  // Samples that end before the last frame, and half of the two options.
  test::write_file(v.csv, test::imu_csv(-1'005'000'000LL, 100'000'000LL, 10'000'000));
  auto e = input_error([&] { (void)open_video_dataset(v.video, v.calib, o); });
  EXPECT_EQ(e, v.csv.string() + ": the IMU samples from -1.005000 s to 0.095000 s do not cover the frames from "
                                "0.050000 s to 0.150000 s (the same clock)");
  o.imu_calib.clear();
  e = input_error([&] { (void)open_video_dataset(v.video, v.calib, o); });
  EXPECT_EQ(e, v.video.string() + ": --imu and --imu-calib go together");
  // A dataset folder brings its own IMU or none.
  o.imu_calib = v.yaml;
  e = input_error([&] { (void)open_dataset(test::make_kitti(tmp.path() / "k", 2), o); });
  EXPECT_NE(e.find("--imu and --imu-calib are for video and camera input"), std::string::npos) << e;
}

// ---- The CLI ----

TEST(ImuCli, InfoReportsTheImuOfAVideoAndNoneWithoutOne) {
  test::TempDir tmp;
  const auto v = make_imu_video(tmp.path());
  const std::string video = "--video " + q(v.video) + " --calib " + q(v.calib);
  const std::string imu = " --imu " + q(v.csv) + " --imu-calib " + q(v.yaml);
  auto r = test::run_cli("info --json " + video + imu);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["format"], "video");
  EXPECT_EQ(j["frames"], 4);
  const auto& i = j["imu"];
  ASSERT_TRUE(i.is_object()) << j;
  EXPECT_EQ(i["path"], v.csv.string());
  EXPECT_EQ(i["samples"], 115);  // -0.495 to +0.645 s at 100 Hz
  EXPECT_EQ(i["rate_hz_nominal"], 200.0);
  EXPECT_NEAR(i["rate_hz_measured"].get<double>(), 100.0, 1e-6);
  EXPECT_NEAR(i["t_first_s"].get<double>(), -0.495, 1e-9);
  EXPECT_NEAR(i["t_last_s"].get<double>(), 0.645, 1e-9);
  EXPECT_EQ(i["frames_t_last_s"], 0.15);
  EXPECT_NEAR(i["T_imu_cam"][0][3].get<double>(), -0.05, 1e-12);
  EXPECT_EQ(i["T_imu_cam"][3], nlohmann::json({0.0, 0.0, 0.0, 1.0}));
  EXPECT_NEAR(i["rotation_deg"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(i["translation_m"].get<double>(), 0.05, 1e-12);
  EXPECT_EQ(i["noise"]["gyroscope_noise_density"], 1.6968e-04);
  EXPECT_EQ(i["noise"]["accelerometer_random_walk"], 3e-3);
  // The measured rate is not the yaml's: said on stderr, stdout stays JSON.
  EXPECT_NE(r.err.find("samples come at 100 Hz, but " + v.yaml.string() + " says rate_hz 200"), std::string::npos)
      << r.err;

  r = test::run_cli("info " + video + imu);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("imu          115 samples, 200.00 Hz nominal, 100.00 Hz measured (median)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("imu span     -0.495 s to +0.645 s from the first frame (frames to +0.150 s)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("imu to cam   T_imu_cam: rotation 0.000 deg, translation (-0.0500, 0.0000, 0.0000) m"),
            std::string::npos)
      << r.out;
  // (RealData.Kitti06Info checks "imu": null in the JSON.)
  r = test::run_cli("info " + q(test::make_euroc(tmp.path() / "e", 2)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\nimu          none\n"), std::string::npos) << r.out;
}

TEST(ImuCli, BadImuInputIsOneLineNamingTheFileAndExit2) {
  test::TempDir tmp;
  const auto v = make_imu_video(tmp.path() / "v");
  const auto euroc = test::make_euroc(tmp.path() / "e", 3);
  test::add_euroc_imu(euroc, 3, -0.02, 1.0);  // starts 20 ms after the first frame
  const std::string video = "--video " + q(v.video) + " --calib " + q(v.calib);
  const auto out = tmp.path() / "out";
  test::write_file(tmp.path() / "back.csv", test::imu_csv(-1'000'000'000LL, 1'000'000'000LL) + ok(0));
  struct Case {
    std::string args;
    std::string message;  // the whole error line after "plslam: error: "
  };
  const Case cases[] = {
      {"info " + video + " --imu " + q(v.csv), "--imu needs --imu-calib FILE"},
      {"info " + q(euroc) + " --imu " + q(v.csv) + " --imu-calib " + q(v.yaml),
       euroc.string() + ": --imu is for --video and --camera input: an EuRoC folder's IMU is its mav0/imu0, and "
                        "KITTI has none"},
      {"info " + q(euroc),
       (euroc / "mav0" / "imu0" / "data.csv").string() +
           ": the IMU samples from 1403715273.020000 s to 1403715274.100000 s do not cover the frames from "
           "1403715273.000000 s to 1403715273.100000 s (the same clock)"},
      {"run " + video + " --imu " + q(tmp.path() / "back.csv") + " --imu-calib " + q(v.yaml) + " --out " + q(out),
       (tmp.path() / "back.csv").string() +
           ": line 403: timestamp 0 is before 1000000000 on line 402: timestamps must increase"},
      {"run --camera " + q(v.video) + " --calib " + q(v.calib) + " --imu " + q(v.csv) + " --imu-calib " +
           q(tmp.path() / "none.yaml") + " --out " + q(out),
       (tmp.path() / "none.yaml").string() + ": file not found"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = test::run_cli(c.args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(r.err, "plslam: error: " + c.message + "\n");
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_FALSE(fs::exists(out / "stats.json"));
}

// ---- Real data ----

// The micro excerpt of V1_01: imu0 at 200 Hz reaches far beyond its 95 frames (and its data.csv
// ends in a line cut short); its T_BS is the identity, so the IMU frame is the body frame.
TEST(RealData, EurocMicroImuIsReadAt200HzAroundTheFrames) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto mav0 = data / "euroc/V1_01_easy_micro/mav0";
  const auto ds = open_dataset(mav0);
  ASSERT_TRUE(ds->imu());
  const auto& imu = *ds->imu();
  const auto& s = imu.samples;
  const double t0 = ds->timestamps().front(), t1 = ds->timestamps().back();
  EXPECT_EQ(imu.calibration.rate_hz, 200.0);
  EXPECT_NEAR(median_rate_hz(s), 200.0, 0.1);
  // The recording starts with the first frame: its first sample has the frame's stamp.
  EXPECT_EQ(s.front().t, t0);
  EXPECT_GE(s.back().t, t1 + kImuMarginS - 0.005);
  EXPECT_LE(s.back().t, t1 + kImuMarginS);
  EXPECT_NEAR(static_cast<double>(s.size()), (t1 - t0 + kImuMarginS) * 200 + 1, 2);
  EXPECT_EQ(imu.calibration.noise.gyro_noise_density, kEurocAdis16448Noise.gyro_noise_density);
  EXPECT_EQ(imu.calibration.noise.acc_random_walk, kEurocAdis16448Noise.acc_random_walk);
  // The drone hovers: the specific force is about gravity, the rotation rate small.
  double acc = 0, gyro = 0;
  for (const auto& x : s) {
    acc += x.acc.norm() / static_cast<double>(s.size());
    gyro = std::max(gyro, x.gyro.norm());
  }
  EXPECT_NEAR(acc, kGravity, 0.3);
  EXPECT_LT(gyro, 0.5);
  // T_imu_cam is cam0's T_BS (T_cam_imu its inverse) up to the rectification's rotation: the same
  // translation, rotations within the rectification's angle, and exactly T_BS * R_rect^T.
  const auto T_BS_cam0 = read_euroc_T_BS(mav0 / "cam0/sensor.yaml");
  const Eigen::Matrix3d& R_rect = ds->rectification_rotation();
  EXPECT_LT((imu.T_imu_cam.translation() - T_BS_cam0.translation()).norm(), 1e-12);
  EXPECT_LT((imu.T_imu_cam.linear() - T_BS_cam0.linear() * R_rect.transpose()).norm(), 1e-12);
  const double rect_deg = Eigen::AngleAxisd(R_rect).angle() * 180 / M_PI;
  const double between_deg =
      Eigen::AngleAxisd(T_BS_cam0.linear().transpose() * imu.T_imu_cam.linear()).angle() * 180 / M_PI;
  EXPECT_NEAR(between_deg, rect_deg, 1e-9);
  EXPECT_LT(rect_deg, 2.0);
  Eigen::Isometry3d T_sensor_rect = Eigen::Isometry3d::Identity();
  T_sensor_rect.linear() = R_rect.transpose();
  EXPECT_LT((imu.T_imu_cam.inverse().matrix() - (T_BS_cam0 * T_sensor_rect).inverse().matrix()).norm(), 1e-12);
  RecordProperty("imu_samples", std::to_string(s.size()));
  RecordProperty("rectification_deg", std::to_string(rect_deg));
}

}  // namespace imu_input_test
}  // namespace plslam::io
