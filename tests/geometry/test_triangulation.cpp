#include <random>

#include <gtest/gtest.h>

#include "optim/synthetic_scene.h"
#include "plslam/geometry/triangulation.h"

namespace plslam::geometry {
namespace {

using test::kitti_like_camera;

// Distance of point X to the infinite 3D line through A and B.
double distance_to_line(const Eigen::Vector3d& X, const Eigen::Vector3d& A, const Eigen::Vector3d& B) {
  return (X - A).cross((B - A).normalized()).norm();
}

TEST(Triangulation, PointsFromTwoViewsAreExact) {
  const StereoCamera cam = kitti_like_camera();
  std::mt19937 rng(1);
  int ok = 0;
  for (int i = 0; i < 1000; ++i) {
    const SE3 T1 = test::random_pose(rng, 2.0, 0.5);
    const SE3 T2 = test::random_pose(rng, 0.3, 0.05) * T1;  // a nearby second view
    const Eigen::Vector3d X = test::world_point_at(cam, T1, test::random_pixel(cam, rng), test::random_depth(rng, 2, 20));
    const Eigen::Vector3d X2 = T2 * X;
    if (X2.z() < 0.5) continue;
    const auto tri = triangulate_point(cam, T1, T2, cam.project(T1 * X), cam.project(X2));
    ASSERT_TRUE(tri.has_value());
    EXPECT_LT((*tri - X).norm(), 1e-6 * X2.z());
    ++ok;
  }
  EXPECT_GT(ok, 900);
}

TEST(Triangulation, PointBehindCameraOrParallelRaysIsRejected) {
  const StereoCamera cam = kitti_like_camera();
  const SE3 T1;
  const SE3 T2(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.5, 0, 0));
  // Same pixel in both views of a pure sideways translation: rays are parallel (point at infinity).
  EXPECT_FALSE(triangulate_point(cam, T1, T2, {600.0, 180.0}, {600.0, 180.0}).has_value());
  // Disparity of the wrong sign: intersection behind the cameras.
  EXPECT_FALSE(triangulate_point(cam, T1, T2, {600.0, 180.0}, {620.0, 180.0}).has_value());
}

TEST(Triangulation, LinesFromTwoViewsLieOnTheTrueLineAndRays) {
  const StereoCamera cam = kitti_like_camera();
  std::mt19937 rng(2);
  int ok = 0;
  for (int i = 0; i < 500; ++i) {
    const SE3 T1 = test::random_pose(rng, 2.0, 0.5);
    const SE3 T2 = test::random_pose(rng, 0.5, 0.1) * T1;
    const auto [A, B] = test::random_segment(cam, T1, rng);
    if ((T2 * A).z() < 0.5 || (T2 * B).z() < 0.5) continue;
    // View 2 sees a different part of the same infinite line.
    const Eigen::Vector3d A2 = A + 0.3 * (B - A), B2 = A + 1.4 * (B - A);
    if ((T2 * B2).z() < 0.5) continue;
    const Segment2d s1{cam.project(T1 * A), cam.project(T1 * B)};
    const Segment2d s2{cam.project(T2 * A2), cam.project(T2 * B2)};
    const auto seg = triangulate_line(cam, T1, T2, s1, s2, 1e-3);
    if (!seg) continue;  // a (near) epipolar line: legitimately rejected
    ++ok;
    // The endpoints are the points of the true line on view 1's endpoint rays: exactly A and B.
    EXPECT_LT((seg->start - A).norm(), 1e-6 * (T1 * A).z()) << i;
    EXPECT_LT((seg->end - B).norm(), 1e-6 * (T1 * B).z()) << i;
    EXPECT_LT(distance_to_line(seg->start, A2, B2), 1e-6 * (T1 * A).z());
  }
  EXPECT_GT(ok, 400);
}

TEST(Triangulation, StereoLineInLeftFrame) {
  const StereoCamera cam = kitti_like_camera();
  std::mt19937 rng(3);
  for (int i = 0; i < 300; ++i) {
    const auto [A, B] = test::random_segment(cam, SE3(), rng);  // left camera frame = world
    const Eigen::Vector3d a = cam.project_stereo(A), b = cam.project_stereo(B);
    // Horizontal segments are degenerate for a horizontal baseline: skip them here.
    if (std::abs(a(1) - b(1)) < 0.1 * (a - b).head<2>().norm()) continue;
    const auto seg = triangulate_stereo_line(cam, {a.head<2>(), b.head<2>()},
                                             {{a(2), a(1)}, {b(2), b(1)}});
    ASSERT_TRUE(seg.has_value()) << a.transpose() << " | " << b.transpose();
    EXPECT_LT((seg->start - A).norm(), 1e-6 * A.z());
    EXPECT_LT((seg->end - B).norm(), 1e-6 * B.z());
  }
  // An exactly horizontal image line lies in the epipolar plane: no intersection.
  const Segment2d left{{100.0, 200.0}, {300.0, 200.0}};
  const Segment2d right{{80.0, 200.0}, {280.0, 200.0}};
  EXPECT_FALSE(triangulate_stereo_line(cam, left, right).has_value());
}

}  // namespace
}  // namespace plslam::geometry
