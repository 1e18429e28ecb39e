#include <random>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/geometry/stereo_rectification.h"

namespace plslam::geometry {
namespace {

// A TUM-VI-like fisheye rig of 150 degrees, the right camera turned by half a degree.
RawStereoRig fisheye_rig() {
  RawStereoRig rig;
  rig.left = {LensModel::kEquidistant, 752, 480, 341.0, 340.0, 367.2, 248.4,
              {0.0034823894, 0.00071520687, -0.0020532361, 0.00020293673}};
  rig.right = {LensModel::kEquidistant, 752, 480, 340.2, 339.1, 380.0, 255.2,
               {0.0034003170, 0.0017067460, -0.0026303960, 0.00036140430}};
  Eigen::Isometry3d T_left_right = Eigen::Isometry3d::Identity();
  T_left_right.translation() = Eigen::Vector3d(0.11, -0.0009, 0.0012);
  T_left_right.linear() = Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d(0.3, 1.0, -0.2).normalized()).toRotationMatrix();
  rig.T_right_left = T_left_right.inverse();
  return rig;
}

RawStereoRig radtan_rig() {  // EuRoC MH01's
  RawStereoRig rig = fisheye_rig();
  rig.left = {LensModel::kRadialTangential, 752, 480, 458.654, 457.296, 367.215, 248.375,
              {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}};
  rig.right = {LensModel::kRadialTangential, 752, 480, 457.587, 456.134, 379.999, 255.238,
               {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05}};
  return rig;
}

// Points seen by both raw cameras land on one row of the rectified pair, at the disparity f b / z,
// and the remap tables send each rectified pixel to the raw pixel of its ray.
void expect_rectified(const RawStereoRig& rig, double balance) {
  const StereoRectification r = rectify_stereo(rig, balance, "test");
  const StereoCalibration& c = r.calibration;
  EXPECT_NEAR(c.baseline, rig.T_right_left.translation().norm(), 1e-9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(-1.5, 1.5), z(1.0, 6.0);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d X(xy(rng), xy(rng), z(rng));  // raw left camera frame
    const Eigen::Vector3d L = r.R_rect_left * X, R = r.R_rect_right * (rig.T_right_left * X);
    if (L.z() < 0.5 || R.z() < 0.5) continue;
    const Eigen::Vector2d pl(c.fx * L.x() / L.z() + c.cx, c.fy * L.y() / L.z() + c.cy);
    const Eigen::Vector2d pr(c.fx * R.x() / R.z() + c.cx, c.fy * R.y() / R.z() + c.cy);
    EXPECT_NEAR(pl.y(), pr.y(), 1e-9);
    EXPECT_NEAR(pl.x() - pr.x(), c.bf() / L.z(), 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 500);
  // Rectified pixel -> raw pixel, as the tables have it (fixed point: 1/32 px).
  const cv::Mat& xy_map = r.map_left[0];
  const cv::Mat& frac = r.map_left[1];
  int inside = 0;
  for (int v = 5; v < c.height; v += 37) {
    for (int u = 5; u < c.width; u += 41) {
      const Eigen::Vector3d ray = r.R_rect_left.transpose() * Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1);
      const auto raw = rig.left.project(ray);
      if (!raw || raw->x() < 0 || raw->y() < 0 || raw->x() > c.width - 1 || raw->y() > c.height - 1) continue;
      const cv::Vec2s whole = xy_map.at<cv::Vec2s>(v, u);
      const int f = frac.at<std::uint16_t>(v, u);
      const Eigen::Vector2d table(whole[0] + (f % 32) / 32.0, whole[1] + (f / 32) / 32.0);
      EXPECT_LT((table - *raw).norm(), 0.05) << u << " " << v;
      ++inside;
    }
  }
  EXPECT_GT(inside, 150);
}

TEST(StereoRectification, RowsAlignAndDisparityIsFocalTimesBaselineOverDepth) {
  expect_rectified(radtan_rig(), 0.0);
  expect_rectified(fisheye_rig(), 0.0);
  expect_rectified(fisheye_rig(), 1.0);
}

// An ideal pair comes out as it went in: nothing to turn, nothing lost, no black border.
TEST(StereoRectification, AnIdealPairIsKeptWhole) {
  RawStereoRig rig;
  rig.left = rig.right = {LensModel::kRadialTangential, 640, 480, 400, 400, 319.5, 239.5, {}};
  rig.T_right_left.translation().x() = -0.2;
  const auto r = rectify_stereo(rig, 0.0, "test");
  EXPECT_NEAR(r.calibration.fx, 400, 1e-6);
  EXPECT_NEAR(r.calibration.cx, 319.5, 1e-6);
  EXPECT_NEAR(r.calibration.baseline, 0.2, 1e-12);
  EXPECT_LT((r.R_rect_left - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(r.coverage.kept_share, 1.0, 1e-9);
  EXPECT_NEAR(r.coverage.blank_share, 0.0, 1e-9);
  EXPECT_NEAR(r.coverage.rect_hfov_deg, r.coverage.raw_hfov_deg, 1e-6);
  EXPECT_NEAR(r.coverage.raw_hfov_deg, 2 * std::atan(319.5 / 400) * 180 / M_PI, 1e-9);
}

// The balance trades the rectified field of view against black borders: a fisheye keeps more of
// its raw image and shows more blank rectified pixels as it grows.
TEST(StereoRectification, BalanceWidensTheRectifiedView) {
  const auto narrow = rectify_stereo(fisheye_rig(), 0.0, "test").coverage;
  const auto wide = rectify_stereo(fisheye_rig(), 1.0, "test").coverage;
  EXPECT_NEAR(narrow.raw_hfov_deg, 126, 2);  // 150 degrees along the diagonal
  EXPECT_LT(narrow.blank_share, 0.01);
  EXPECT_GT(wide.rect_hfov_deg, narrow.rect_hfov_deg + 15);
  EXPECT_GT(wide.kept_share, narrow.kept_share + 0.15);
  EXPECT_GT(wide.blank_share, 0.1);
}

TEST(StereoRectification, RefusesWhatCannotBeRectified) {
  auto rig = fisheye_rig();
  EXPECT_THROW(rectify_stereo(rig, 1.5, "test"), InputError);
  rig.T_right_left.translation().setZero();
  EXPECT_THROW(rectify_stereo(rig, 0.0, "test"), InputError);
  rig = fisheye_rig();
  rig.right.model = LensModel::kRadialTangential;
  EXPECT_THROW(rectify_stereo(rig, 0.0, "test"), InputError);
  rig = fisheye_rig();
  rig.T_right_left = rig.T_right_left.inverse();  // the right camera on the left
  try {
    rectify_stereo(rig, 0.0, "cam1/sensor.yaml");
    ADD_FAILURE() << "a swapped rig was rectified";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("baseline must be positive"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plslam::geometry
