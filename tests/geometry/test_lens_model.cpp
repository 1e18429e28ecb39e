#include <random>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "plslam/geometry/lens_model.h"

namespace plslam::geometry {
namespace {

LensCamera euroc_like() {  // EuRoC MH01's cam0
  return {LensModel::kRadialTangential, 752, 480, 458.654, 457.296, 367.215, 248.375,
          {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}};
}

LensCamera tumvi_like() {  // TUM-VI's cam0 (512x512, 190 degrees)
  return {LensModel::kEquidistant, 512, 512, 190.978, 190.973, 254.932, 256.897,
          {0.0034823894, 0.00071520687, -0.0020532361, 0.00020293673}};
}

cv::Mat K_of(const LensCamera& c) { return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1); }

TEST(LensModel, ParsesTheNamesOfSensorYaml) {
  EXPECT_EQ(parse_lens_model("radial-tangential"), LensModel::kRadialTangential);
  EXPECT_EQ(parse_lens_model("radtan"), LensModel::kRadialTangential);
  EXPECT_EQ(parse_lens_model("equidistant"), LensModel::kEquidistant);
  EXPECT_EQ(parse_lens_model("fisheye"), LensModel::kEquidistant);
  EXPECT_FALSE(parse_lens_model("omni").has_value());
  EXPECT_STREQ(to_string(LensModel::kEquidistant), "equidistant");
}

// The models are OpenCV's: projectPoints (k3 = 0) and fisheye::projectPoints give the same pixels.
TEST(LensModel, ProjectionsAreOpenCvs) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-0.8, 0.8);
  for (const LensCamera& cam : {euroc_like(), tumvi_like()}) {
    std::vector<cv::Point3d> rays;
    for (int i = 0; i < 200; ++i) rays.emplace_back(xy(rng), xy(rng), 1.0);
    std::vector<cv::Point2d> expected;
    const cv::Mat rvec = cv::Mat::zeros(3, 1, CV_64F), tvec = cv::Mat::zeros(3, 1, CV_64F);
    if (cam.model == LensModel::kRadialTangential) {
      const cv::Mat D = (cv::Mat_<double>(1, 5) << cam.coeffs[0], cam.coeffs[1], cam.coeffs[2], cam.coeffs[3], 0);
      cv::projectPoints(rays, rvec, tvec, K_of(cam), D, expected);
    } else {
      const cv::Mat D = (cv::Mat_<double>(1, 4) << cam.coeffs[0], cam.coeffs[1], cam.coeffs[2], cam.coeffs[3]);
      cv::fisheye::projectPoints(rays, expected, rvec, tvec, K_of(cam), D);
    }
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const auto p = cam.project(Eigen::Vector3d(rays[i].x, rays[i].y, rays[i].z) * 2.5);
      ASSERT_TRUE(p.has_value());
      EXPECT_NEAR(p->x(), expected[i].x, 1e-9);
      EXPECT_NEAR(p->y(), expected[i].y, 1e-9);
    }
  }
}

// Unprojection inverts projection to far below a thousandth of a pixel over the whole image,
// also past 90 degrees for the fisheye.
TEST(LensModel, UnprojectionInvertsProjectionOverTheImage) {
  for (const LensCamera& cam : {euroc_like(), tumvi_like()}) {
    for (int y = 0; y < cam.height; y += 7) {
      for (int x = 0; x < cam.width; x += 7) {
        const Eigen::Vector2d px(x, y);
        const auto ray = cam.unproject(px);
        ASSERT_TRUE(ray.has_value()) << x << " " << y;
        EXPECT_NEAR(ray->norm(), 1.0, 1e-12);
        const auto back = cam.project(*ray);
        ASSERT_TRUE(back.has_value());
        EXPECT_LT((*back - px).norm(), 1e-8) << x << " " << y;
      }
    }
  }
  const auto widest = tumvi_like().max_ray_angle();
  ASSERT_TRUE(widest.has_value());
  EXPECT_GT(*widest, M_PI / 2);  // TUM-VI's corners look behind the camera's plane
}

// With no coefficients, the equidistant model puts angle theta at radius f theta, so the corner
// of a square image of half-size f * pi / 4 looks 45 degrees sideways along each axis' diagonal.
TEST(LensModel, EquidistantRadiusIsTheAngle) {
  const double f = 300;
  const LensCamera cam{LensModel::kEquidistant, 601, 601, f, f, 300, 300, {}};
  const auto ray = cam.unproject({300 + f * 0.5, 300});
  ASSERT_TRUE(ray.has_value());
  EXPECT_NEAR(std::atan2(ray->x(), ray->z()), 0.5, 1e-12);
  EXPECT_NEAR(*cam.max_ray_angle(), std::hypot(300.0, 300.0) / f, 1e-9);
  // Behind the camera: 120 degrees off axis still has a pixel.
  const auto p = cam.project({std::sin(2.0944), 0, std::cos(2.0944)});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), 300 + f * 2.0944, 1e-9);
  EXPECT_FALSE(cam.project({0, 0, -1}).has_value());
}

// Where a strong barrel distortion folds over, no ray is reported rather than a wrong one, and
// a radial-tangential camera sees nothing behind it.
TEST(LensModel, NoRayWhereTheDistortionFoldsOver) {
  const LensCamera cam{LensModel::kRadialTangential, 1000, 1000, 200, 200, 500, 500, {-0.5, 0.0, 0.0, 0.0}};
  // x_d = x (1 - 0.5 x^2) peaks at x = sqrt(2/3), x_d = 0.544: 108.9 px from the centre.
  EXPECT_TRUE(cam.unproject({500 + 100, 500}).has_value());
  EXPECT_FALSE(cam.unproject({500 + 120, 500}).has_value());
  EXPECT_FALSE(cam.max_ray_angle().has_value());
  EXPECT_FALSE(cam.project({0.1, 0, -1}).has_value());
}

}  // namespace
}  // namespace plslam::geometry
