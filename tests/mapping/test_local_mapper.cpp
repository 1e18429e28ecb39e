// The local mapper's thread seams: pause() waits for the keyframe in progress and is counted, an
// abort is meant for the BA in progress only, and process_pending() is untouched by either. The
// map: four keyframes 0.3 m apart sharing 60 points at 3 m, the third one's pose perturbed, so
// that local BA around the fourth has something to correct.
#include <gtest/gtest.h>

#include "plslam/mapping/local_mapper.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace local_mapper_test {

using test::camera_at;
using test::range;

struct Row {
  test::SyntheticMap m;
  std::vector<map::KeyFrame*> kf;
  geometry::SE3 truth2;
  Row() {
    for (int i = 0; i < 60; ++i) m.world.add_point({-0.4 + 0.02 * i, -0.3 + 0.01 * i, 3.0 + 0.01 * (i % 7)});
    for (int k = 0; k < 4; ++k) kf.push_back(m.add_keyframe(camera_at({0.3 * k, 0, 0})));
    for (auto* k : kf) m.observe_points(k, range(0, 60));
    truth2 = kf[2]->pose();
    kf[2]->set_pose(geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.004, -0.003, 0.002)) * truth2);
  }
  double error2() const { return (kf[2]->camera_center() - truth2.inverse().translation()).norm(); }
};

LocalMapperOptions no_culling() {
  LocalMapperOptions o;
  o.keyframe_culling.redundancy = 1.1;  // every keyframe sees every point: keep them all
  return o;
}

TEST(LocalMapperThread, AnAbortRaisedWhileIdleDoesNotCutTheNextKeyframesBa) {
  Row r;
  ASSERT_GT(r.error2(), 1e-3);
  LocalMapper mapper(r.m.map, no_culling());
  mapper.start();
  mapper.abort_ba();  // nothing runs: the flag is cleared when the keyframe starts
  mapper.insert(r.kf[3]);
  mapper.wait_idle();
  mapper.stop();
  const auto st = mapper.stats();
  EXPECT_EQ(st.local_ba_ms.size(), 1u);
  EXPECT_EQ(st.aborted_local_ba, 0);
  EXPECT_LT(r.error2(), 1e-4);
}

TEST(LocalMapperThread, PauseHoldsTheQueueUntilResumeAndIsTimed) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  mapper.start();
  mapper.pause();
  mapper.insert(r.kf[3]);
  EXPECT_EQ(mapper.queued(), 1u);  // paused: it waits
  EXPECT_GT(r.error2(), 1e-3);
  mapper.resume();
  mapper.wait_idle();
  mapper.stop();
  const auto st = mapper.stats();
  ASSERT_EQ(st.pause_wait_ms.size(), 1u);
  EXPECT_GE(st.pause_wait_ms[0], 0.0);
  EXPECT_EQ(st.local_ba_ms.size(), 1u);
  EXPECT_LT(r.error2(), 1e-4);
}

// The longest queue is what a growing backlog would show (issue 19): two keyframes wait while
// mapping is paused, and only the last one, with nothing behind it, gets the local BA.
TEST(LocalMapperThread, TheLongestQueueIsCounted) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  mapper.start();
  mapper.pause();
  mapper.insert(r.kf[2]);
  mapper.insert(r.kf[3]);
  EXPECT_EQ(mapper.queued(), 2u);
  mapper.resume();
  mapper.wait_idle();
  mapper.stop();
  const auto st = mapper.stats();
  EXPECT_EQ(st.max_queue, 2);
  EXPECT_EQ(st.keyframe_ms.size(), 2u);
  EXPECT_EQ(st.local_ba_ms.size(), 1u);  // the first one had another waiting: no BA
}

// Deterministic mode: the caller's thread runs the keyframe; an abort raised before has no effect.
TEST(LocalMapperSequential, ProcessPendingRunsTheFullBaWhateverWasRaisedBefore) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  mapper.abort_ba();
  mapper.insert(r.kf[3]);
  mapper.process_pending();
  const auto st = mapper.stats();
  EXPECT_EQ(st.local_ba_ms.size(), 1u);
  EXPECT_EQ(st.aborted_local_ba, 0);
  EXPECT_TRUE(st.pause_wait_ms.empty());
  EXPECT_EQ(st.max_queue, 1);
  EXPECT_LT(r.error2(), 1e-4);
}

// Deterministic mode's pipeline: the keyframe is processed up to its local BA, whose solver reads
// only its window; the map is untouched until finish_deferred(), which writes the result back and
// hands the keyframe on. Meanwhile the mapper is neither idle nor pausable (the window points at
// landmarks that reclamation would free). The result is process_pending()'s, bit for bit.
TEST(LocalMapperSequential, ADeferredBaWritesNothingUntilFinishedAndEqualsTheImmediateOne) {
  Row immediate;
  LocalMapper reference(immediate.m.map, no_culling());
  reference.insert(immediate.kf[3]);
  reference.process_pending();

  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  std::vector<map::KeyFrame*> handed_on;
  mapper.set_keyframe_sink([&](map::KeyFrame* kf) { handed_on.push_back(kf); });
  mapper.insert(r.kf[3]);
  const geometry::SE3 before = r.kf[2]->pose();
  mapper.process_pending_deferring_ba();
  EXPECT_EQ(mapper.queued(), 0u);
  EXPECT_FALSE(mapper.idle());
  EXPECT_FALSE(mapper.try_pause());
  mapper.optimise_deferred_ba();
  EXPECT_TRUE(r.kf[2]->pose().matrix() == before.matrix()) << "the solver wrote into the map";
  EXPECT_TRUE(handed_on.empty());
  EXPECT_TRUE(mapper.stats().local_ba_ms.empty());
  mapper.finish_deferred();
  EXPECT_TRUE(mapper.idle());
  ASSERT_EQ(handed_on.size(), 1u);
  EXPECT_EQ(handed_on[0], r.kf[3]);
  EXPECT_EQ(mapper.stats().local_ba_ms.size(), 1u);
  EXPECT_EQ(mapper.stats().keyframe_ms.size(), 1u);
  EXPECT_LT(r.error2(), 1e-4);
  EXPECT_TRUE(r.kf[2]->pose().matrix() == immediate.kf[2]->pose().matrix());
  for (int w = 0; w < 60; ++w) {
    ASSERT_TRUE(r.m.point[w]->position() == immediate.m.point[w]->position()) << "point " << w;
  }
}

// The next keyframe finishes a deferred one first, so keyframes are mapped in order.
TEST(LocalMapperSequential, TheNextKeyframeFinishesTheDeferredOneFirst) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  std::vector<map::KeyFrame*> handed_on;
  mapper.set_keyframe_sink([&](map::KeyFrame* kf) { handed_on.push_back(kf); });
  mapper.insert(r.kf[2]);
  mapper.process_pending_deferring_ba();
  EXPECT_TRUE(handed_on.empty());
  mapper.insert(r.kf[3]);
  mapper.process_pending_deferring_ba();
  ASSERT_EQ(handed_on.size(), 1u);
  EXPECT_EQ(handed_on[0], r.kf[2]);
  mapper.process_pending();  // nothing queued: finishes the deferred one
  ASSERT_EQ(handed_on.size(), 2u);
  EXPECT_EQ(handed_on[1], r.kf[3]);
  EXPECT_EQ(mapper.stats().local_ba_ms.size(), 2u);
  EXPECT_TRUE(mapper.idle());
}

// Deterministic mode: keyframes that waited together (a loop correction held them) are all mapped
// in full, and the last one's local BA covers the others, free in its window: none is skipped.
TEST(LocalMapperSequential, KeyframesWaitingTogetherShareTheLastOnesBaAndNoneIsSkipped) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  mapper.insert(r.kf[2]);
  mapper.insert(r.kf[3]);
  mapper.process_pending_deferring_ba();
  EXPECT_EQ(mapper.deferred_ba_observations(), 4u * 60u);  // 0 is the origin: fixed, but observing
  mapper.finish_deferred();
  const auto st = mapper.stats();
  EXPECT_EQ(st.keyframe_ms.size(), 2u);
  EXPECT_EQ(st.fusion_ms.size(), 2u);
  EXPECT_EQ(st.local_ba_ms.size(), 1u);
  EXPECT_EQ(st.covered_local_ba, 1);
  EXPECT_EQ(st.skipped_local_ba, 0);
  EXPECT_LT(r.error2(), 1e-4);
}

// Reclamation's seam: try_pause() holds an idle mapper only, and the held mapper takes no keyframe.
TEST(LocalMapperThread, TryPauseHoldsOnlyAnIdleMapper) {
  Row r;
  LocalMapper mapper(r.m.map, no_culling());
  mapper.start();
  ASSERT_TRUE(mapper.try_pause());
  mapper.insert(r.kf[3]);
  EXPECT_EQ(mapper.queued(), 1u);
  EXPECT_FALSE(mapper.try_pause());  // something waits: not idle
  mapper.resume();
  mapper.wait_idle();
  EXPECT_EQ(mapper.queued(), 0u);
  EXPECT_TRUE(mapper.try_pause());
  mapper.resume();
  mapper.stop();
  EXPECT_EQ(mapper.stats().local_ba_ms.size(), 1u);
}

// Tracking associates a keyframe with the points it tracked; local mapping adds the observations
// later. A point culled in between must leave the keyframe's slot, or it would outlive its
// reclamation there.
TEST(LocalMapperSequential, APointCulledBeforeItsKeyframeIsProcessedLeavesTheSlot) {
  Row r;
  int slot = -1;
  map::MapPoint* q = nullptr;
  const auto points = r.kf[3]->map_points();
  for (std::size_t i = 0; i < points.size() && !q; ++i) {
    if (points[i]) {
      q = points[i];
      slot = static_cast<int>(i);
    }
  }
  ASSERT_NE(q, nullptr);
  q->erase_observation(r.kf[3]);  // as tracking leaves it: in the slot, not observed
  ASSERT_EQ(r.kf[3]->map_point(slot), q);
  q->set_bad();  // culled by local mapping meanwhile
  EXPECT_EQ(r.kf[3]->map_point(slot), q);
  LocalMapper mapper(r.m.map, no_culling());
  mapper.insert(r.kf[3]);
  mapper.process_pending();
  // Empty, or a point triangulated there since (the keypoint became free in both keyframes).
  EXPECT_NE(r.kf[3]->map_point(slot), q);
  EXPECT_EQ(r.m.map.reclaim([&] { mapper.drop_bad_landmarks(); }).points, 1);
  for (auto* k : r.kf) {
    for (auto* p : k->map_points()) {
      if (p) {
        EXPECT_FALSE(p->is_bad());
      }
    }
  }
}

}  // namespace local_mapper_test
}  // namespace plslam::mapping
