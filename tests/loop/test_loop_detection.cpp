// Loop detection and verification on the circling camera of loop_scene.h.
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "loop/loop_scene.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/loop/loop_detector.h"
#include "plslam/loop/loop_verifier.h"
#include "plslam/map/map.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::loop {
namespace {

using namespace test;  // NOLINT: the scene's names

TEST(LoopDetection, TheSecondLapFindsTheFirstAfterThreeConsistentKeyframesAndNeverBefore) {
  Scene s;
  LoopDetector detector(*s.db);
  int first_detection = -1;
  for (int k = 0; k < kKeyframes; ++k) {
    map::KeyFrame* kf = s.add_keyframe(k);
    const auto found = detector.detect(kf);
    if (k < kPerLap) {
      // The first lap's look-alikes are all covisible: no loop.
      EXPECT_TRUE(found.empty()) << "keyframe " << k << " found " << (found.empty() ? -1 : found[0].keyframe->frame_id()) << " score " << (found.empty() ? 0 : found[0].score) << " covisibles " << kf->covisibles().size();
      continue;
    }
    for (const auto& f : found) {
      // The same place: the first lap's keyframe within two keyframes (16 degrees) of this one.
      EXPECT_LE(std::abs(f.keyframe->frame_id() - (k - kPerLap)), 2) << "keyframe " << k;
      EXPECT_GE(f.consistency, 3);
    }
    if (!found.empty() && first_detection < 0) first_detection = k;
  }
  // Keyframe 45 has no covisible neighbour yet; 46, 47 and 48 find the place in a row.
  EXPECT_GE(first_detection, kPerLap + 2);
  EXPECT_LE(first_detection, kPerLap + 4);
}

TEST(LoopVerification, RecoversTheRelativePoseOfATrueLoop) {
  Scene s;
  for (int k = 0; k < kKeyframes; ++k) s.add_keyframe(k);
  map::KeyFrame* query = s.keyframes[kPerLap + 5];
  map::KeyFrame* candidate = s.keyframes[5];
  const auto c = verify_loop(query, candidate, *s.db);
  ASSERT_TRUE(c);
  EXPECT_GE(c->matches.size(), 100u);
  // The truth: both keyframes see the same place from the same true pose.
  const geometry::SE3 truth = true_pose(kPerLap + 5) * true_pose(5).inverse();
  const geometry::SE3 err = truth.inverse() * c->T_query_candidate;
  EXPECT_LT(err.translation().norm(), 0.02);
  EXPECT_LT(Eigen::AngleAxisd(err.rotation()).angle(), 0.5 * std::numbers::pi / 180);
  // And the drift follows from it: T_qw(corrected) = T_qc * T_cw; the query's estimate is off by it.
  const geometry::SE3 corrected = c->T_query_candidate * candidate->pose();
  EXPECT_LT((corrected.inverse().translation() - true_pose(kPerLap + 5).inverse().translation()).norm(), 0.05);
  for (const auto& [a, b] : c->matches) {
    EXPECT_LT((drift().inverse() * a->position() - b->position()).norm(), 1e-9);
  }
}

TEST(LoopVerification, PixelErrorsNotLooseDepthsSetThePose) {
  Scene s;
  for (int k = 0; k < kKeyframes; ++k) s.add_keyframe(k);
  map::KeyFrame* query = s.keyframes[kPerLap + 5];
  map::KeyFrame* candidate = s.keyframes[5];
  // The candidate's farther half of points sit 10 % too far along their rays, as far stereo
  // depths can: in pixels they are where they were, in metres they are off by 0.6-1 m.
  const geometry::SE3 Tc = candidate->pose();
  std::vector<double> depths;
  for (map::MapPoint* p : candidate->map_points()) {
    if (p) depths.push_back((Tc * p->position()).z());
  }
  std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2), depths.end());
  const double median = depths[depths.size() / 2];
  for (map::MapPoint* p : candidate->map_points()) {
    if (p && (Tc * p->position()).z() > median) p->set_position(Tc.inverse() * (1.1 * (Tc * p->position())));
  }
  const auto c = verify_loop(query, candidate, *s.db);
  ASSERT_TRUE(c);
  // A 3D refit of the inliers, as the verification did before, is pulled along the view by the far
  // half, loses inliers round by round and rejects this true loop. Pixel errors find the pose.
  const geometry::SE3 truth = true_pose(kPerLap + 5) * true_pose(5).inverse();
  const geometry::SE3 err = truth.inverse() * c->T_query_candidate;
  EXPECT_LT(err.translation().norm(), 0.05);
  EXPECT_LT(Eigen::AngleAxisd(err.rotation()).angle(), 0.5 * std::numbers::pi / 180);
}

TEST(LoopVerification, RejectsDistantPlacesAndAliasedGeometry) {
  Scene s;
  for (int k = 0; k < kKeyframes; ++k) s.add_keyframe(k);
  // Half a lap apart: nothing in common.
  EXPECT_FALSE(verify_loop(s.keyframes[kPerLap + 5], s.keyframes[5 + kPerLap / 2], *s.db));
  // Perceptual aliasing: a keyframe that looks exactly like keyframe 5 (same features) but whose
  // map points lie at random places. The matches agree on no single transform.
  map::KeyFrame* original = s.keyframes[5];
  auto copy = std::make_shared<map::FrameData>(original->data());
  copy->frame_id = 1000;
  map::KeyFrame* alias = s.map.create_keyframe(copy, original->pose());
  std::uniform_real_distribution<double> u(-12, 12);
  for (std::size_t j = 0; j < copy->keypoints.size(); ++j) {
    map::MapPoint* mp = s.map.create_point(Eigen::Vector3d(u(s.rng), u(s.rng), u(s.rng)), alias, 1000);
    mp->add_observation(alias, static_cast<int>(j));
    alias->add_map_point(mp, static_cast<int>(j));
  }
  s.db->add(alias);
  EXPECT_TRUE(verify_loop(s.keyframes[kPerLap + 5], original, *s.db));
  EXPECT_FALSE(verify_loop(s.keyframes[kPerLap + 5], alias, *s.db));
  LoopVerifierOptions bad;
  bad.min_inliers = 2;
  EXPECT_THROW(verify_loop(s.keyframes[kPerLap + 5], original, *s.db, bad), std::invalid_argument);
}

}  // namespace
}  // namespace plslam::loop
