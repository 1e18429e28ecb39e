#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/mapping/epipolar_index.h"

namespace plslam::mapping {
namespace {

struct TwoViews {
  Eigen::Matrix3d K;
  Eigen::Matrix3d R21;  // camera 1 -> camera 2
  Eigen::Vector3d t21;
};

Eigen::Vector2d project(const Eigen::Matrix3d& K, const Eigen::Vector3d& X) {
  const Eigen::Vector3d x = K * X;
  return x.head<2>() / x.z();
}

// Two views related by `motion` (camera 2's centre in camera 1) and a small random rotation;
// `n` points in front of both cameras, seen in a 1226x370 image, their image-2 positions moved
// by up to `noise` pixels. Every point must come back from the query of its own ray.
void check_motion(const Eigen::Vector3d& motion, double noise, std::mt19937& rng, double* mean_share) {
  std::uniform_real_distribution<double> unit(-1, 1);
  TwoViews g;
  g.K << 707, 0, 601, 0, 707, 183, 0, 0, 1;
  const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
  g.R21 = Eigen::AngleAxisd(0.05 * unit(rng), axis).toRotationMatrix();
  g.t21 = -g.R21 * motion;
  std::vector<Eigen::Vector2d> x1, x2;
  while (x1.size() < 1500) {
    const Eigen::Vector3d X(30 * unit(rng), 8 * unit(rng), 1.0 + 40 * (unit(rng) + 1));
    const Eigen::Vector3d X2 = g.R21 * X + g.t21;
    if (X2.z() < 0.5) continue;
    const Eigen::Vector2d p1 = project(g.K, X), p2 = project(g.K, X2);
    if (p1.x() < 0 || p1.x() > 1226 || p1.y() < 0 || p1.y() > 370) continue;
    if (p2.x() < 0 || p2.x() > 1226 || p2.y() < 0 || p2.y() > 370) continue;
    const double a = 3.14159 * unit(rng);
    x1.push_back(p1);
    x2.push_back(p2 + noise * std::abs(unit(rng)) * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  const EpipolarIndex index(x2, g.K * g.t21, noise + 1e-9);
  const Eigen::Matrix3d H = g.K * g.R21 * g.K.inverse();
  std::vector<int> out;
  double returned = 0;
  for (int i = 0; i < static_cast<int>(x1.size()); ++i) {
    EpipolarIndex::Ray ray;
    const Eigen::Vector3d v = H * Eigen::Vector3d(x1[static_cast<std::size_t>(i)].x(), x1[static_cast<std::size_t>(i)].y(), 1.0);
    if (index.ray(v, &ray)) {
      index.query(ray, &out);
      ASSERT_TRUE(index.along_segment(ray, x2[static_cast<std::size_t>(i)], noise + 1e-9))
          << "point " << i << " off its segment, motion " << motion.transpose();
    } else {
      index.query_all(&out);
    }
    std::sort(out.begin(), out.end());
    ASSERT_EQ(std::adjacent_find(out.begin(), out.end()), out.end()) << "duplicates";
    ASSERT_TRUE(std::binary_search(out.begin(), out.end(), i))
        << "point " << i << " missed, motion " << motion.transpose();
    returned += static_cast<double>(out.size());
  }
  *mean_share = returned / static_cast<double>(x1.size() * x1.size());
}

TEST(EpipolarIndex, EveryTrueCorrespondenceIsACandidate) {
  std::mt19937 rng(7);
  double share = 0;
  // forward, backward, oblique, sideways, vertical, and nearly pure rotation
  for (const Eigen::Vector3d& motion : {Eigen::Vector3d(0, 0, 2.4), Eigen::Vector3d(0, 0, -1.5),
                                       Eigen::Vector3d(0.8, 0.1, 1.0), Eigen::Vector3d(1.0, 0, 0),
                                       Eigen::Vector3d(0, -0.5, 0.02), Eigen::Vector3d(1e-4, 0, 1e-4)}) {
    for (const double noise : {0.5, 2.0, 7.0}) {
      check_motion(motion, noise, rng, &share);
      EXPECT_LT(share, 0.6) << "motion " << motion.transpose();
    }
  }
}

TEST(EpipolarIndex, ForwardMotionReadsAFewPercent) {
  std::mt19937 rng(3);
  double share = 1;
  check_motion({0, 0, 2.4}, 2.0, rng, &share);
  RecordProperty("share_forward", std::to_string(share));
  EXPECT_LT(share, 0.03);
  check_motion({1.0, 0, 0.2}, 2.0, rng, &share);
  RecordProperty("share_oblique", std::to_string(share));
  EXPECT_LT(share, 0.04);
}

// Camera 2 one metre ahead of camera 1: a ray's points in front of camera 2 project from its
// vanishing point (here the pixel itself) outwards; the epipolar line's part between the epipole
// and the vanishing point, and behind the epipole, holds no match.
TEST(EpipolarIndex, ForwardMotionSegmentStartsAtTheVanishingPoint) {
  Eigen::Matrix3d K;
  K << 707, 0, 601, 0, 707, 183, 0, 0, 1;
  const Eigen::Vector3d t21(0, 0, -1);  // camera 1's centre seen from camera 2
  const Eigen::Vector2d e(601, 183), x1(800, 250);
  const EpipolarIndex index({x1}, K * t21, 2.0);
  EpipolarIndex::Ray ray;
  ASSERT_TRUE(index.ray(Eigen::Vector3d(x1.x(), x1.y(), 1.0), &ray));
  EXPECT_NEAR(ray.start, (x1 - e).norm(), 1e-9);
  EXPECT_TRUE(std::isinf(ray.length));
  for (const double depth : {1.5, 3.0, 10.0, 100.0}) {
    const Eigen::Vector3d X = depth * K.inverse() * Eigen::Vector3d(x1.x(), x1.y(), 1.0) + t21;
    EXPECT_TRUE(index.along_segment(ray, project(K, X), 2.0)) << "depth " << depth;
  }
  EXPECT_TRUE(index.along_segment(ray, x1 - 1.5 * (x1 - e).normalized(), 2.0));  // within the band
  EXPECT_FALSE(index.along_segment(ray, e + 0.5 * (x1 - e), 2.0));               // before the start
  EXPECT_FALSE(index.along_segment(ray, e - (x1 - e), 2.0));                     // behind the epipole
  // Looking backwards (the ray's third component negative) nothing is in front of camera 2.
  ASSERT_TRUE(index.ray(Eigen::Vector3d(-x1.x(), -x1.y(), -1.0), &ray));
  EXPECT_FALSE(index.along_segment(ray, x1, 2.0));
}

TEST(EpipolarIndex, EpipoleAtInfinityReturnsAll) {
  const std::vector<Eigen::Vector2d> points = {{1, 2}, {300, 40}, {10, 10}};
  const EpipolarIndex index(points, {1.0, 0.0, 0.0}, 3.0);
  EpipolarIndex::Ray ray;
  EXPECT_FALSE(index.ray({100, 100, 1}, &ray));
  std::vector<int> out;
  index.query_all(&out);
  EXPECT_EQ(out, (std::vector<int>{0, 1, 2}));
}

TEST(EpipolarIndex, EmptyIndexReturnsNothing) {
  const EpipolarIndex empty({}, {100, 100, 1}, 3.0);
  EpipolarIndex::Ray ray;
  ASSERT_TRUE(empty.ray({300, 120, 1}, &ray));
  std::vector<int> out{5};
  empty.query(ray, &out);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace plslam::mapping
