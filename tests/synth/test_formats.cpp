// The written datasets parse back: KITTI calib/times/poses, EuRoC csv/yaml/ground truth, the
// synth/ extras, and the project's own dataset readers see exactly the rendered sequence.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "plslam/io/calibration_file.h"
#include "plslam/io/dataset.h"
#include "plslam/io/video_dataset.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/synth/writer.h"
#include "support/test_support.h"

namespace plslam::synth {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::vector<double> numbers(const std::string& s) {
  std::istringstream in(s);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

void expect_pose_near(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tol) {
  EXPECT_LE((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tol) << a.matrix() << "\nvs\n" << b.matrix();
}

SequenceOptions small(SceneKind scene, CameraPreset preset) {
  SequenceOptions o;
  o.scene = scene;
  o.preset = preset;
  o.frames = 4;
  o.seed = 3;
  return o;
}

TEST(SynthFormats, Kitti) {
  test::TempDir tmp;
  const Sequence seq(small(SceneKind::kStreet, kitti_preset()));
  write_sequence(seq, tmp.path(), OutputFormat::kKitti, {}, 1);
  const fs::path s = tmp.path() / "sequences" / "00";
  const auto calib = lines(s / "calib.txt");
  ASSERT_GE(calib.size(), 2u);
  ASSERT_EQ(calib[0].rfind("P0: ", 0), 0u);
  ASSERT_EQ(calib[1].rfind("P1: ", 0), 0u);
  const auto p0 = numbers(calib[0].substr(4)), p1 = numbers(calib[1].substr(4));
  ASSERT_EQ(p0.size(), 12u);
  ASSERT_EQ(p1.size(), 12u);
  EXPECT_NEAR(p0[0], 718.856, 1e-9);
  EXPECT_NEAR(p0[3], 0.0, 1e-12);
  EXPECT_NEAR(p1[3], -718.856 * 0.54, 1e-6);
  EXPECT_NEAR(p1[2], p0[2], 1e-12);
  EXPECT_NEAR(p1[6], p0[6], 1e-12);

  const auto times = lines(s / "times.txt");
  ASSERT_EQ(times.size(), 4u);
  for (std::size_t i = 0; i < times.size(); ++i) EXPECT_NEAR(std::stod(times[i]), i * 0.1, 1e-9);

  const auto poses = io::read_trajectory(tmp.path() / "poses" / "00.txt", io::TrajectoryFormat::kKitti);
  ASSERT_EQ(poses.size(), 4u);
  expect_pose_near(poses[0].T, Eigen::Isometry3d::Identity(), 0);
  const Eigen::Isometry3d T0inv = seq.left_pose(0).inverse();
  for (std::size_t i = 0; i < 4; ++i) expect_pose_near(poses[i].T, T0inv * seq.left_pose(i), 1e-9);
  // KITTI camera convention: z forward. The car drives forward, so z grows.
  EXPECT_GT(poses[3].T.translation().z(), 1.5);
  EXPECT_LT(std::abs(poses[3].T.translation().x()), 0.5);

  for (const char* cam : {"image_0", "image_1"}) {
    const cv::Mat img = cv::imread((s / cam / "000003.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.type(), CV_8UC1);
    EXPECT_EQ(img.cols, 1241);
    EXPECT_EQ(img.rows, 376);
  }
  // Extras are in the first-camera frame: the GT points project into frame 0 where rendered.
  const auto seg = lines(s / "synth" / "segments_3d.txt");
  EXPECT_EQ(seg.size(), seq.scene().edges().size() + 1);
  EXPECT_EQ(numbers(seg[1]).size(), 6u);
  const auto pts = lines(s / "synth" / "points_3d.txt");
  EXPECT_GT(pts.size(), 100u);
  const auto left = io::read_trajectory(s / "synth" / "left_camera.tum", io::TrajectoryFormat::kTum);
  ASSERT_EQ(left.size(), 4u);
  expect_pose_near(left[2].T, poses[2].T, 1e-9);

  // The project's reader sees the same sequence.
  const auto ds = io::open_dataset(s);
  EXPECT_EQ(ds->size(), 4u);
  EXPECT_NEAR(ds->calibration().baseline, 0.54, 1e-9);
  EXPECT_NEAR(ds->calibration().fx, 718.856, 1e-9);
  EXPECT_NEAR(ds->fps(), 10.0, 1e-6);
  ASSERT_TRUE(ds->ground_truth().has_value());
  expect_pose_near(ds->ground_truth()->at(3).T, poses[3].T, 1e-9);
}

TEST(SynthFormats, Euroc) {
  test::TempDir tmp;
  const Sequence seq(small(SceneKind::kOffice, euroc_preset()));
  write_sequence(seq, tmp.path(), OutputFormat::kEuroc, {}, 2);
  const fs::path mav = tmp.path() / "mav0";
  for (int cam = 0; cam < 2; ++cam) {
    const fs::path c = mav / ("cam" + std::to_string(cam));
    const auto csv = lines(c / "data.csv");
    ASSERT_EQ(csv.size(), 5u);
    EXPECT_EQ(csv[0], "#timestamp [ns],filename");
    EXPECT_EQ(csv[1], "1000000000,1000000000.png");
    EXPECT_EQ(csv[2], "1050000000,1050000000.png");
    const cv::Mat img = cv::imread((c / "data" / "1150000000.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.type(), CV_8UC1);
    EXPECT_EQ(img.cols, 752);
    EXPECT_EQ(img.rows, 480);
  }
  // sensor.yaml: the real EuRoC keys; cam1 = cam0 shifted by the baseline along cam0's x.
  auto read_T = [](const fs::path& p) {
    const YAML::Node y = YAML::LoadFile(p.string());
    const auto d = y["T_BS"]["data"].as<std::vector<double>>();
    EXPECT_EQ(d.size(), 16u);
    EXPECT_EQ(y["resolution"].as<std::vector<int>>(), (std::vector<int>{752, 480}));
    EXPECT_EQ(y["camera_model"].as<std::string>(), "pinhole");
    EXPECT_EQ(y["distortion_model"].as<std::string>(), "radial-tangential");
    EXPECT_EQ(y["distortion_coefficients"].as<std::vector<double>>(), (std::vector<double>{0, 0, 0, 0}));
    EXPECT_EQ(y["rate_hz"].as<double>(), 20.0);
    const auto k = y["intrinsics"].as<std::vector<double>>();
    EXPECT_EQ(k, (std::vector<double>{458.0, 458.0, 375.5, 239.5}));
    Eigen::Matrix4d M;
    for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = d[i];
    Eigen::Isometry3d T;
    T.matrix() = M;
    return T;
  };
  const Eigen::Isometry3d T_BS0 = read_T(mav / "cam0" / "sensor.yaml"), T_BS1 = read_T(mav / "cam1" / "sensor.yaml");
  const Eigen::Isometry3d T_c0c1 = T_BS0.inverse() * T_BS1;
  expect_pose_near(T_c0c1, Eigen::Isometry3d(Eigen::Translation3d(0.11, 0, 0)), 1e-12);
  EXPECT_GT((T_BS0.matrix() - Eigen::Matrix4d::Identity()).norm(), 0.5);  // a real transform

  // Ground truth is the body: body * T_BS = the rendered left camera (p_body = T_BS p_cam).
  const auto gt = io::read_trajectory(mav / "state_groundtruth_estimate0" / "data.csv", io::TrajectoryFormat::kEuroc);
  ASSERT_EQ(gt.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(gt[i].t, 1.0 + 0.05 * i, 1e-9);
    expect_pose_near(gt[i].T * T_BS0, seq.left_pose(i), 1e-9);
  }
  const auto seg = lines(mav / "synth" / "segments_3d.txt");
  EXPECT_EQ(seg.size(), seq.scene().edges().size() + 1);

  // The project's reader: same calibration, same images (rectification of an ideal pair is
  // the identity), ground truth of the left camera.
  const auto ds = io::open_dataset(tmp.path());
  ASSERT_EQ(ds->size(), 4u);
  const auto& c = ds->calibration();
  EXPECT_NEAR(c.fx, 458.0, 1e-6);
  EXPECT_NEAR(c.cx, 375.5, 1e-6);
  EXPECT_NEAR(c.cy, 239.5, 1e-6);
  EXPECT_NEAR(c.baseline, 0.11, 1e-9);
  EXPECT_NEAR(ds->fps(), 20.0, 1e-6);
  ASSERT_TRUE(ds->ground_truth().has_value());
  ASSERT_EQ(ds->ground_truth()->size(), 4u);
  expect_pose_near(ds->ground_truth()->at(2).T, seq.left_pose(2), 1e-9);
  // The IMU (the body frame), read back by the project's reader: the synthetic samples exactly, on
  // the images' clock (EuRoC stamps start at 1 s), covering the frames.
  ASSERT_TRUE(ds->imu().has_value());
  expect_pose_near(ds->imu()->T_imu_cam, T_BS0, 1e-12);
  const SyntheticImu imu(seq, euroc_T_BS_cam0(), {}, imu_seed(seq.options()));
  const auto& read = ds->imu()->samples;
  ASSERT_GE(read.size(), 40u);
  EXPECT_LE(read.front().t, 1.0);
  EXPECT_GE(read.back().t, 1.15);
  std::size_t matched = 0;
  for (const ImuSample& r : read) {
    for (const ImuSample& w : imu.samples()) {
      if (std::abs(w.t + 1.0 - r.t) > 1e-9) continue;
      EXPECT_EQ(r.gyro, w.gyro);
      EXPECT_EQ(r.acc, w.acc);
      ++matched;
    }
  }
  EXPECT_EQ(matched, read.size());
  const YAML::Node imu_yaml = YAML::LoadFile((mav / "imu0" / "sensor.yaml").string());
  EXPECT_EQ(imu_yaml["rate_hz"].as<double>(), 200.0);
  EXPECT_EQ(imu_yaml["gyroscope_noise_density"].as<double>(), kEurocAdis16448Noise.gyro_noise_density);

  const auto frame = ds->load(1);
  const cv::Mat raw = cv::imread((mav / "cam0" / "data" / "1050000000.png").string(), cv::IMREAD_GRAYSCALE);
  const double diff = cv::norm(frame.left, raw, cv::NORM_L1) / raw.total();
  std::printf("reader-rectified vs written left image: mean |diff| %.4f grey levels\n", diff);
  EXPECT_LT(diff, 0.5);
}

// The video layout: a lossless side-by-side video, read back through the project's video reader
// as exactly the rendered images, with its calibration file and ground truth in the scene's world.
// The KITTI preset's odd width (1241) and the threads' out-of-order rendering are both covered.
TEST(SynthFormats, Video) {
  test::TempDir tmp;
  auto o = small(SceneKind::kStreet, kitti_preset());
  o.frames = 21;  // more than one batch of chunks with 2 threads
  const Sequence seq(o);
  ASSERT_TRUE(write_sequence(seq, tmp.path(), OutputFormat::kVideo, {}, 2));
  const auto c = io::read_calibration_file(tmp.path() / kVideoCalibrationFile);
  EXPECT_EQ(c.width, 1241);
  EXPECT_EQ(c.height, 376);
  EXPECT_EQ(c.fx, 718.856);
  EXPECT_EQ(c.baseline, 0.54);
  const auto ds = io::open_video_dataset(tmp.path() / kVideoFile, tmp.path() / kVideoCalibrationFile);
  ASSERT_EQ(ds->size(), 21u);
  EXPECT_NEAR(ds->fps(), 10.0, 1e-9);
  ASSERT_TRUE(ds->ground_truth().has_value());
  ASSERT_EQ(ds->ground_truth()->size(), 21u);
  StereoRenderer renderer(seq);
  for (std::size_t i : {0u, 7u, 20u}) {
    EXPECT_DOUBLE_EQ(ds->ground_truth()->at(i).t, ds->timestamps()[i]);
    expect_pose_near(ds->ground_truth()->at(i).T, seq.left_pose(i), 1e-12);
    const auto frame = ds->load(i);
    const auto im = renderer.render(i);
    EXPECT_EQ(cv::norm(frame.left, im.left, cv::NORM_INF), 0) << i;
    EXPECT_EQ(cv::norm(frame.right, im.right, cv::NORM_INF), 0) << i;
  }
  EXPECT_TRUE(fs::is_regular_file(tmp.path() / "synth" / "synth.json"));
  EXPECT_EQ(lines(tmp.path() / "synth" / "segments_3d.txt").size(), seq.scene().edges().size() + 1);
}

TEST(SynthFormats, CliAndInfo) {
  test::TempDir tmp;
  const auto out = tmp.path() / "seq";
  const auto r = test::run_cli("synth --out " + out.string() + " --scene corridor --frames 6 --seed 5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("6/6 frames"), std::string::npos) << r.err;  // progress
  const auto info = test::run_cli("info --json " + out.string());
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["frames"], 6);
  EXPECT_EQ(j["width"], 752);
  EXPECT_EQ(j["height"], 480);
  EXPECT_NEAR(j["fps"].get<double>(), 20.0, 1e-6);
  EXPECT_NEAR(j["baseline_m"].get<double>(), 0.11, 1e-9);
  EXPECT_EQ(j["has_ground_truth"], true);

  const auto k = tmp.path() / "k";
  const auto rk = test::run_cli("synth --out " + k.string() + " --scene street --preset kitti --frames 3");
  ASSERT_EQ(rk.exit_code, 0) << rk.err;
  const auto ik = test::run_cli("info --json " + (k / "sequences" / "00").string());
  ASSERT_EQ(ik.exit_code, 0) << ik.err;
  const auto jk = nlohmann::json::parse(ik.out);
  EXPECT_EQ(jk["frames"], 3);
  EXPECT_EQ(jk["width"], 1241);
  EXPECT_EQ(jk["height"], 376);
  EXPECT_NEAR(jk["fps"].get<double>(), 10.0, 1e-6);
  EXPECT_NEAR(jk["baseline_m"].get<double>(), 0.54, 1e-9);
  EXPECT_EQ(jk["has_ground_truth"], true);

  // Bad usage -> exit 2 with a one-line message.
  EXPECT_EQ(test::run_cli("synth --out " + out.string() + " --scene moon").exit_code, 2);
  EXPECT_EQ(test::run_cli("synth --out " + out.string() + " --preset tum").exit_code, 2);
  const auto loop = test::run_cli("synth --out " + out.string() + " --loop --frames 50");
  EXPECT_EQ(loop.exit_code, 2);
  EXPECT_NE(loop.err.find("needs at least"), std::string::npos) << loop.err;
}

TEST(SynthFormats, SameSeedSameFiles) {
  test::TempDir tmp;
  for (const char* d : {"a", "b"})
    ASSERT_EQ(test::run_cli("synth --out " + (tmp.path() / d).string() + " --frames 3 --seed 11").exit_code, 0);
  for (const char* name : {"1000000000.png", "1100000000.png"}) {
    auto slurp = [](const fs::path& p) {
      std::ifstream in(p, std::ios::binary);
      return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const auto a = slurp(tmp.path() / "a" / "mav0" / "cam1" / "data" / name);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, slurp(tmp.path() / "b" / "mav0" / "cam1" / "data" / name));
  }
}

}  // namespace
}  // namespace plslam::synth
