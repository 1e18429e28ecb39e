// ORB-SLAM2's quadtree distribution: count, strongest point kept, spread, determinism.
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "plslam/features/keypoint_uniformity.h"
#include "plslam/features/quadtree.h"

namespace plslam::features {
namespace {

std::vector<cv::KeyPoint> clustered_keypoints(int n, cv::Size size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::set<std::pair<int, int>> used;
  std::vector<cv::KeyPoint> kps;
  while (static_cast<int>(kps.size()) < n) {
    const bool cluster = static_cast<int>(kps.size()) < n * 8 / 10;
    const int w = cluster ? size.width / 4 : size.width, h = cluster ? size.height / 4 : size.height;
    const int x = static_cast<int>(rng() % static_cast<uint32_t>(w)), y = static_cast<int>(rng() % static_cast<uint32_t>(h));
    if (!used.insert({x, y}).second) continue;
    const float score = cluster ? static_cast<float>(150 + rng() % 100) : static_cast<float>(7 + rng() % 140);
    kps.emplace_back(cv::Point2f(static_cast<float>(x), static_cast<float>(y)), 7.f, -1.f, score);
  }
  return kps;
}

TEST(Quadtree, KeepsTargetCountStrongestFirstAndTheGlobalMaximum) {
  const cv::Size size(752, 480);
  auto kps = clustered_keypoints(10000, size, 1u);
  kps[4321].response = 1000.f;
  for (const int target : {1, 37, 400, 1200}) {
    const auto kept = quadtree_select(kps, target, size);
    EXPECT_EQ(static_cast<int>(kept.size()), target);
    EXPECT_EQ(kept.front(), 4321);  // the strongest point wins its node, whatever the node
    for (std::size_t i = 1; i < kept.size(); ++i)
      EXPECT_GE(kps[static_cast<std::size_t>(kept[i - 1])].response, kps[static_cast<std::size_t>(kept[i])].response);
    std::set<int> unique(kept.begin(), kept.end());
    EXPECT_EQ(unique.size(), kept.size());
  }
}

TEST(Quadtree, SpreadsClusteredPoints) {
  const cv::Size size(752, 480);
  const auto kps = clustered_keypoints(10000, size, 2u);
  const auto kept = quadtree_select(kps, 400, size);
  std::vector<cv::KeyPoint> sel;
  for (int i : kept) sel.push_back(kps[static_cast<std::size_t>(i)]);
  EXPECT_LT(grid_count_cv(sel, size), 0.8);
  int in_cluster = 0;
  for (const auto& k : sel)
    if (k.pt.x < size.width / 4 && k.pt.y < size.height / 4) ++in_cluster;
  EXPECT_LT(in_cluster, 400 / 4);
}

TEST(Quadtree, DeterministicAndSmallInputs) {
  const cv::Size size(640, 480);
  const auto kps = clustered_keypoints(5000, size, 3u);
  EXPECT_EQ(quadtree_select(kps, 300, size), quadtree_select(kps, 300, size));
  const std::vector<cv::KeyPoint> few(kps.begin(), kps.begin() + 20);
  EXPECT_EQ(quadtree_select(few, 50, size).size(), 20u);
  EXPECT_TRUE(quadtree_select(kps, 0, size).empty());
  // A portrait image (W < H) still gets one initial node.
  EXPECT_EQ(quadtree_select(kps, 100, cv::Size(480, 640)).size(), 100u);
}

TEST(Quadtree, CornersGiveTheKeypointSelection) {
  // Column widths that are whole (1200 / 3) and not, and many initial columns (3000 / 300).
  for (const cv::Size size : {cv::Size(752, 480), cv::Size(1226, 370), cv::Size(1200, 400), cv::Size(97, 61), cv::Size(3000, 300)}) {
    const auto kps = clustered_keypoints(size.area() / 30, size, 4u + static_cast<uint32_t>(size.width));
    const FastCorners corners = FastCorners::from_keypoints(kps);
    for (const int target : {1, 37, 400, 1200})
      EXPECT_EQ(quadtree_select(corners, target, size), quadtree_select(kps, target, size)) << size << " target " << target;
  }
}

}  // namespace
}  // namespace plslam::features
