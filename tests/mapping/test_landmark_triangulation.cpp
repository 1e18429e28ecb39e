// Two-view triangulation of new points and lines between a keyframe and its covisible neighbour,
// on views whose keypoints are exact: the positions must come back to 1e-6 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "plslam/mapping/landmark_triangulation.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace triangulation_test {

using test::camera_at;

// Keyframe 1 at the origin, keyframe 2 moved sideways by `offset` metres. With offset 1 image 2
// is image 1 shifted left by fx / z = 400 / z pixels, a float-exact number at the depths used, so
// the free keypoints of both images are exact projections. 20 points both keyframes already map
// give them their covisibility edge.
struct TwoKeyframes {
  test::SyntheticMap m;
  map::KeyFrame* kf1 = nullptr;
  map::KeyFrame* kf2 = nullptr;
  std::vector<int> free_points, segments;

  explicit TwoKeyframes(double offset = 1.0) {
    const geometry::SE3 T1 = camera_at({0, 0, 0}), T2 = camera_at({offset, 0, 0});
    std::vector<int> shared;
    for (int i = 0; i < 20; ++i) shared.push_back(m.world.add_point_seen_at(T1, {300.0 + 15 * i, 60.0}, 3.0));
    for (double z : {2.0, 4.0, 5.0, 8.0, 10.0, 16.0, 20.0}) {
      for (double u : {250.5, 400.0, 517.25, 600.0}) {
        for (double v : {120.5, 300.0, 410.75}) free_points.push_back(m.world.add_point_seen_at(T1, {u, v}, z));
      }
    }
    // Vertical segments (across the epipolar lines), fronto-parallel at 4 and 8 m.
    for (const auto& [u, z] : {std::pair{450.0, 4.0}, std::pair{500.0, 8.0}}) {
      segments.push_back(m.world.add_segment(T1.inverse() * m.world.camera().unproject({u, 100.5}, z),
                                             T1.inverse() * m.world.camera().unproject({u, 380.0}, z)));
    }
    kf1 = m.add_keyframe(T1);
    kf2 = m.add_keyframe(T2);
    m.observe_points(kf1, shared);
    m.observe_points(kf2, shared);
  }
};

TEST(LandmarkTriangulation, RecoversPointsAndLinesExactly) {
  TwoKeyframes s;
  ASSERT_EQ(s.kf1->best_covisibles(10), std::vector<map::KeyFrame*>{s.kf2});
  const NewLandmarks made = triangulate_new_landmarks(s.m.map, *s.kf1, TriangulationOptions{});
  ASSERT_EQ(made.points.size(), s.free_points.size());
  for (int w : s.free_points) {
    const int i1 = s.m.keypoint_of(s.kf1, w), i2 = s.m.keypoint_of(s.kf2, w);
    ASSERT_GE(i2, 0) << "world point " << w << " out of view 2";
    map::MapPoint* mp = s.kf1->map_point(i1);
    ASSERT_NE(mp, nullptr) << "world point " << w << " not triangulated";
    EXPECT_EQ(s.kf2->map_point(i2), mp) << "paired with the wrong keypoint";
    EXPECT_EQ(mp->num_observations(), 2);
    EXPECT_LT((mp->position() - s.m.world.points[static_cast<std::size_t>(w)]).norm(), 1e-6);
    EXPECT_TRUE(std::count(made.points.begin(), made.points.end(), mp));
  }
  ASSERT_EQ(made.lines.size(), s.segments.size());
  for (int k : s.segments) {
    map::MapLine* ml = s.kf1->map_line(s.m.line_of(s.kf1, k));
    ASSERT_NE(ml, nullptr);
    EXPECT_EQ(s.kf2->map_line(s.m.line_of(s.kf2, k)), ml);
    const auto& truth = s.m.world.segments[static_cast<std::size_t>(k)];
    EXPECT_LT((ml->start() - truth.first).norm(), 1e-6);
    EXPECT_LT((ml->end() - truth.second).norm(), 1e-6);
  }
}

TEST(LandmarkTriangulation, SkipsANeighbourCloserThanTheMinimumBaseline) {
  TwoKeyframes s(0.09);  // under one stereo baseline (0.1 m)
  const NewLandmarks made = triangulate_new_landmarks(s.m.map, *s.kf1, TriangulationOptions{});
  EXPECT_TRUE(made.points.empty());
  EXPECT_TRUE(made.lines.empty());
}

TEST(LandmarkTriangulation, SkipsRaysWithTooLittleParallax) {
  TwoKeyframes s;
  TriangulationOptions o;
  o.max_parallax_cos = 0.99;
  o.lines = false;
  const NewLandmarks made = triangulate_new_landmarks(s.m.map, *s.kf1, o);
  std::set<int> expected;
  for (int w : s.free_points) {
    const Eigen::Vector3d X = s.m.world.points[static_cast<std::size_t>(w)];
    const double cos = X.normalized().dot((X - Eigen::Vector3d(1, 0, 0)).normalized());
    if (cos <= 0.99) expected.insert(w);
  }
  ASSERT_FALSE(expected.empty());
  ASSERT_LT(expected.size(), s.free_points.size());
  std::set<int> got;
  for (int w : s.free_points) {
    if (s.kf1->map_point(s.m.keypoint_of(s.kf1, w))) got.insert(w);
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(made.points.size(), expected.size());
  EXPECT_TRUE(made.lines.empty());
}

TEST(LandmarkTriangulation, PairsKeypointsAlongEpipolarLinesUnderGeneralMotion) {
  // Camera 2 moves forward and sideways and turns: the epipolar index, not a fall-back, finds the
  // candidates. Keypoints are float roundings of the projections, so 1e-4 m instead of 1e-6.
  test::SyntheticMap m;
  const geometry::SE3 T1 = camera_at({0, 0, 0});
  const geometry::SE3 T2 =
      geometry::SE3(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix(), Eigen::Vector3d::Zero()) *
      camera_at({0.6, 0.1, 0.5});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(40, 600), v(40, 440), inv_z(1 / 12.0, 1 / 3.0);
  std::vector<int> shared, free_points;
  for (int i = 0; i < 200; ++i) {
    const int w = m.world.add_point_seen_at(T1, {u(rng), v(rng)}, 1 / inv_z(rng));
    (i < 20 ? shared : free_points).push_back(w);
  }
  map::KeyFrame* kf1 = m.add_keyframe(T1);
  map::KeyFrame* kf2 = m.add_keyframe(T2);
  m.observe_points(kf1, shared);
  m.observe_points(kf2, shared);
  ASSERT_EQ(kf1->best_covisibles(10).size(), 1u);
  const NewLandmarks made = triangulate_new_landmarks(m.map, *kf1, TriangulationOptions{});
  int seen_by_both = 0;
  for (int w : free_points) {
    const int i2 = m.keypoint_of(kf2, w);
    map::MapPoint* mp = kf1->map_point(m.keypoint_of(kf1, w));
    if (i2 < 0) {
      EXPECT_EQ(mp, nullptr);
      continue;
    }
    ++seen_by_both;
    ASSERT_NE(mp, nullptr) << "world point " << w;
    EXPECT_EQ(kf2->map_point(i2), mp);
    EXPECT_LT((mp->position() - m.world.points[static_cast<std::size_t>(w)]).norm(), 1e-4);
  }
  EXPECT_GT(seen_by_both, 100);
  EXPECT_EQ(static_cast<int>(made.points.size()), seen_by_both);
}

}  // namespace triangulation_test
}  // namespace plslam::mapping
