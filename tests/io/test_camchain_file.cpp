// The raw calibration file (Kalibr's camchain layout) that plslam calibrate writes and --calib
// reads: a round trip, Kalibr's own files, a one-line error naming the file and the key for bad
// content, and the rectification an input builds from it.
#include <cmath>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/camchain_file.h"
#include "plslam/io/euroc_sensor.h"
#include "support/test_support.h"

namespace plslam::io {
namespace camchain_file_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

// TUM-VI's room1 camchain (equidistant), as Kalibr writes it, extra keys and all.
const char* const kKalibr = R"(cam0:
  T_cam_imu:
  - [-0.99952504, 0.00750192, -0.02989013, 0.04557484]
  - [0.02961534, -0.03439736, -0.99896935, -0.07116180]
  - [-0.00852233, -0.99938008, 0.03415885, -0.04468125]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182]
  distortion_model: equidistant
  intrinsics: [190.97847715128717, 190.9733070521226, 254.93170605935475, 256.8974428996504]
  resolution: [512, 512]
  rostopic: /cam0/image_raw
cam1:
  T_cam_imu:
  - [-0.99951105, 0.00810408, -0.03019914, -0.05545634]
  - [0.03029912, 0.01251164, -0.99946257, -0.06925002]
  - [-0.00772188, -0.99988889, -0.01275107, -0.04745286]
  - [0.0, 0.0, 0.0, 1.0]
  T_cn_cnm1:
  - [0.9999994317488622, -0.0008361847221513937, -0.0006612844045898121, -0.10092123225528335]
  - [0.0008042457277382264, 0.9988989443471681, -0.04690684567228134, -0.001964540595211977]
  - [0.0006997790813734836, 0.04690628718225568, 0.9988990492196964, -0.0014652733635300777]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  cam_overlaps: [0]
  distortion_coeffs: [0.0034003170790442797, 0.001766278153469831, -0.00266312569781606, 0.0003299517423931039]
  distortion_model: equidistant
  intrinsics: [190.44236969414825, 190.4344384721956, 252.59949716835982, 254.91723064636983]
  resolution: [512, 512]
  rostopic: /cam1/image_raw
  timeshift_cam_imu: 0.0
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(CamchainFile, ReadsKalibrsFileAndRoundTrips) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "camchain.yaml", kKalibr);
  const UserCalibration user = read_user_calibration(tmp.path() / "camchain.yaml");
  ASSERT_TRUE(user.raw);
  ASSERT_FALSE(user.rectified);
  const auto& rig = *user.raw;
  EXPECT_EQ(rig.left.model, geometry::LensModel::kEquidistant);
  EXPECT_EQ(rig.left.width, 512);
  EXPECT_DOUBLE_EQ(rig.right.fx, 190.44236969414825);
  EXPECT_DOUBLE_EQ(rig.left.coeffs[3], 0.00020293673591811182);
  EXPECT_NEAR(rig.T_right_left.translation().x(), -0.10092123225528335, 1e-15);

  write_camchain_file(tmp.path() / "out.yaml", rig, "a comment\nover two lines");
  const auto back = read_camchain_file(tmp.path() / "out.yaml");
  for (const auto& [a, b] : {std::pair{&rig.left, &back.left}, std::pair{&rig.right, &back.right}}) {
    EXPECT_EQ(a->fx, b->fx);
    EXPECT_EQ(a->cy, b->cy);
    EXPECT_EQ(a->coeffs, b->coeffs);
    EXPECT_EQ(a->model, b->model);
  }
  EXPECT_LT((rig.T_right_left.matrix() - back.T_right_left.matrix()).norm(), 1e-12);

  // The rectified pair an input builds: the right camera 10 cm to the right, and the maps to remap with.
  const InputRectification rect = rectify_user_calibration(user, 0.0, tmp.path() / "camchain.yaml");
  ASSERT_TRUE(rect.rectification);
  EXPECT_NEAR(rect.calibration.baseline, rig.T_right_left.translation().norm(), 1e-9);
  EXPECT_EQ(rect.calibration.width, 512);
  EXPECT_FALSE(rect.rectification->map_left[0].empty());

  // The other inputs' reader refuses it, saying why.
  try {
    (void)read_calibration_file(tmp.path() / "camchain.yaml");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("raw cameras"), std::string::npos) << e.what();
  }
}

TEST(CamchainFile, ANoneDistortionIsAPinhole) {
  test::TempDir tmp;
  std::string text = kKalibr;
  for (int i = 0; i < 2; ++i) {
    const auto a = text.find("  distortion_coeffs:");
    text.erase(a, text.find('\n', a) - a + 1);
    text = replace(text, "distortion_model: equidistant", "distortion_model: none");
  }
  test::write_file(tmp.path() / "c.yaml", text);
  const auto rig = read_camchain_file(tmp.path() / "c.yaml");
  EXPECT_EQ(rig.left.model, geometry::LensModel::kRadialTangential);
  EXPECT_EQ(rig.left.coeffs, (std::array<double, 4>{}));
}

// plslam calibrate's other output: a sensor.yaml per camera, whatever its comment holds.
TEST(CamchainFile, EurocSensorYamlRoundTripsWithAnyComment) {
  test::TempDir tmp;
  EurocCameraSensor s;
  s.T_BS.translate(Eigen::Vector3d(0.1, -0.02, 0.003));
  s.T_BS.rotate(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()));
  s.width = 512;
  s.height = 512;
  s.fu = 190.97847715128717;
  s.fv = 190.9733070521226;
  s.cu = 254.93170605935475;
  s.cv = 256.8974428996504;
  s.distortion_model = geometry::LensModel::kEquidistant;
  s.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182};
  write_euroc_camera_yaml(tmp.path() / "sensor.yaml", s, "cam1 (body frame: cam0) # \"quoted\" \\ and\na line");
  const auto back = read_euroc_camera_yaml(tmp.path() / "sensor.yaml");
  EXPECT_EQ(back.lens().fx, s.fu);
  EXPECT_EQ(back.lens().cy, s.cv);
  EXPECT_EQ(back.distortion, s.distortion);
  EXPECT_EQ(back.distortion_model, s.distortion_model);
  EXPECT_TRUE(back.T_BS.isApprox(s.T_BS, 1e-12));
}

TEST(CamchainFile, BadContentIsAOneLineErrorNamingTheKey) {
  const std::string cam1_T = "  T_cn_cnm1:\n  - [0.9999994317488622";
  const struct {
    std::string text, key, problem;
  } cases[] = {
      {replace(kKalibr, "  rostopic: /cam1/image_raw\n", "  rostopik: /cam1\n"), "cam1.rostopik", "unknown key"},
      {std::string(kKalibr) + "cam2:\n  resolution: [512, 512]\n", "cam2", "unknown key"},
      {replace(kKalibr, cam1_T, "  T_cn_cnm2:\n  - [0.9999994317488622"), "T_cn_cnm2", "unknown key"},
      {replace(kKalibr, "  T_cn_cnm1:\n", "  T_x:\n"), "T_x", "unknown key"},
      {replace(kKalibr, "resolution: [512, 512]\n  rostopic: /cam1", "resolution: [640, 512]\n  rostopic: /cam1"),
       "cam1.resolution", "differs"},
      {replace(kKalibr, "camera_model: pinhole", "camera_model: omni"), "cam0.camera_model", "not supported"},
      {replace(kKalibr, "distortion_model: equidistant", "distortion_model: radtan"), "cam1.distortion_model",
       "differs"},
      {replace(kKalibr, "distortion_model: equidistant", "distortion_model: fov"), "cam0.distortion_model",
       "not supported"},
      {replace(kKalibr, "[0.0034823894022493434,", "[0.0034823894022493434, 0,"), "cam0.distortion_coeffs", "needs 4"},
      {replace(kKalibr, "[0.0034823894022493434,", "[-2.0,"), "cam0", "folds over"},
      {replace(kKalibr, "[190.97847715128717,", "[-190.9,"), "cam0.intrinsics", "positive"},
      {replace(kKalibr, "[0.9999994317488622,", "[1.5,"), "cam1.T_cn_cnm1", "rigid"},
      {replace(kKalibr, "[0.9999994317488622,", "[.nan,"), "cam1.T_cn_cnm1", "non-finite"},
      {replace(kKalibr, "resolution: [512, 512]\n  rostopic: /cam0", "resolution: [512.5, 512]\n  rostopic: /cam0"),
       "cam0.resolution", "whole numbers"},
      {replace(kKalibr, "intrinsics: [190.97847715128717", "intrinsics: {a: [190.97847715128717"), "", "malformed"},
  };
  test::TempDir tmp;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.key + " / " + c.problem);
    const fs::path p = tmp.path() / "camchain.yaml";
    test::write_file(p, c.text);
    try {
      (void)read_user_calibration(p);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_EQ(msg.rfind(p.string() + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(c.key), std::string::npos) << msg;
      EXPECT_NE(msg.find(c.problem), std::string::npos) << msg;
    }
  }
}

}  // namespace camchain_file_test
}  // namespace plslam::io
