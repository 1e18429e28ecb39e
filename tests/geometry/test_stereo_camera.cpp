#include <random>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/geometry/stereo_camera.h"

namespace plslam::geometry {
namespace {

const StereoCamera kCam(718.856, 718.856, 607.1928, 185.2157, 386.1448, 1241, 376);

TEST(StereoCamera, FromCalibration) {
  StereoCalibration c;
  c.width = 640; c.height = 480; c.fx = 400; c.fy = 410; c.cx = 320; c.cy = 240; c.baseline = 0.1;
  const StereoCamera cam(c);
  EXPECT_DOUBLE_EQ(cam.bf(), 40.0);
  EXPECT_DOUBLE_EQ(cam.baseline(), 0.1);
  c.fx = 0;
  EXPECT_THROW(StereoCamera{c}, InputError);
}

TEST(StereoCamera, RightProjectionIsTheRightCameraPinhole) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(-10, 10), z(0.5, 80);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d X(xy(rng), xy(rng), z(rng));
    const Eigen::Vector3d p = kCam.project_stereo(X);
    // The right camera sits at +b along x: its frame sees X - (b, 0, 0).
    const Eigen::Vector2d pr = kCam.project(X - Eigen::Vector3d(kCam.baseline(), 0, 0));
    EXPECT_NEAR(p(2), pr.x(), 1e-9);
    EXPECT_NEAR(p(1), pr.y(), 1e-9);
    EXPECT_NEAR(p(0) - p(2), kCam.bf() / X.z(), 1e-9);
    EXPECT_LT((kCam.project(X) - p.head<2>()).norm(), 1e-12);
    // Unprojection from the stereo observation recovers the point.
    const auto back = kCam.unproject_stereo(p);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((*back - X).norm(), 1e-9 * X.z());
    EXPECT_LT((kCam.unproject(p.head<2>(), X.z()) - X).norm(), 1e-9);
    EXPECT_LT((kCam.ray(p.head<2>()) * X.z() - X).norm(), 1e-9);
  }
  EXPECT_FALSE(kCam.unproject_stereo({100.0, 50.0, 100.0}).has_value());
  EXPECT_FALSE(kCam.unproject_stereo({100.0, 50.0, 101.0}).has_value());
}

TEST(StereoCamera, LineThroughGivesSignedPixelDistance) {
  const Eigen::Vector3d l = line_through({10.0, 10.0}, {110.0, 10.0});  // horizontal v = 10
  EXPECT_NEAR(l.head<2>().norm(), 1.0, 1e-15);
  EXPECT_NEAR(std::abs(l.dot(Eigen::Vector3d(50.0, 13.0, 1.0))), 3.0, 1e-12);
  EXPECT_NEAR(l.dot(Eigen::Vector3d(500.0, 10.0, 1.0)), 0.0, 1e-12);
  const Eigen::Vector3d m = line_through({0.0, 0.0}, {3.0, 4.0});
  EXPECT_NEAR(std::abs(m.dot(Eigen::Vector3d(4.0, -3.0, 1.0))), 5.0, 1e-12);
}

TEST(StereoCamera, InImage) {
  EXPECT_TRUE(kCam.in_image({0.0, 0.0}));
  EXPECT_FALSE(kCam.in_image({0.0, 0.0}, 1.0));
  EXPECT_FALSE(kCam.in_image({1241.0, 10.0}));
  EXPECT_TRUE(kCam.in_image({1240.5, 375.5}));
}

}  // namespace
}  // namespace plslam::geometry
