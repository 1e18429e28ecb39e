// Recent landmark culling: the probation rules on landmarks with known observations.
#include <gtest/gtest.h>

#include "plslam/mapping/landmark_culling.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace landmark_culling_test {

using test::camera_at;

// Four stereo keyframes 0.2 m apart that all see 30 points and 3 vertical segments.
struct FourKeyframes {
  test::SyntheticMap m;
  std::vector<map::KeyFrame*> kf;
  FourKeyframes() {
    for (int i = 0; i < 30; ++i) m.world.add_point({-1.0 + 0.07 * i, -0.5 + 0.03 * i, 3.0});
    for (int k = 0; k < 3; ++k) m.world.add_segment({-0.5 + 0.5 * k, -0.5, 4.0}, {-0.5 + 0.5 * k, 0.5, 4.0});
    for (int k = 0; k < 4; ++k) kf.push_back(m.add_keyframe(camera_at({0.2 * k, 0, 0})));
  }
};

TEST(LandmarkCulling, AWellObservedPointSurvivesProbationAndAPoorlyObservedOneIsCulled) {
  FourKeyframes s;
  // Made by keyframe 1. Weak: only its maker observes it (weight 2, one stereo keyframe).
  // Good: two stereo keyframes (weight 4). Unfound: well observed, but tracking found it in
  // 1 of 10 frames that should have seen it.
  map::MapPoint* weak = s.m.observe_point(s.kf[1], 0);
  map::MapPoint* good = s.m.observe_point(s.kf[1], 1);
  s.m.observe_point(s.kf[2], 1);
  map::MapPoint* unfound = s.m.observe_point(s.kf[1], 2);
  s.m.observe_point(s.kf[2], 2);
  s.m.observe_point(s.kf[3], 2);
  unfound->increase_visible(9);
  ASSERT_EQ(weak->observation_weight(), 2);
  ASSERT_EQ(good->observation_weight(), 4);

  RecentLandmarks recent;
  for (auto* p : {weak, good, unfound}) recent.add(p, s.kf[1]->id());
  auto culled = recent.cull(s.kf[2]->id());  // one keyframe later: only the found ratio applies
  EXPECT_EQ(culled.points, 1);
  EXPECT_TRUE(unfound->is_bad());
  EXPECT_EQ(s.kf[2]->map_point(s.m.keypoint_of(s.kf[2], 2)), nullptr);  // gone from its keyframes
  EXPECT_FALSE(weak->is_bad());
  EXPECT_EQ(recent.points_on_probation(), 2u);

  culled = recent.cull(s.kf[3]->id());  // two keyframes later: the observation rule too
  EXPECT_EQ(culled.points, 1);
  EXPECT_TRUE(weak->is_bad());
  EXPECT_FALSE(good->is_bad());
  EXPECT_EQ(recent.points_on_probation(), 1u);

  culled = recent.cull(s.kf[3]->id() + 1);  // past probation: forgotten, not culled
  EXPECT_EQ(culled.points, 0);
  EXPECT_FALSE(good->is_bad());
  EXPECT_EQ(recent.points_on_probation(), 0u);
}

TEST(LandmarkCulling, LinesNeedThreeObservingKeyframes) {
  FourKeyframes s;
  map::MapLine* two = s.m.observe_line(s.kf[1], 0);
  s.m.observe_line(s.kf[2], 0);
  map::MapLine* three = s.m.observe_line(s.kf[1], 1);
  s.m.observe_line(s.kf[2], 1);
  s.m.observe_line(s.kf[3], 1);
  ASSERT_EQ(two->observation_weight(), 4);  // enough for a point, not for a line
  RecentLandmarks recent;
  recent.add(two, s.kf[1]->id());
  recent.add(three, s.kf[1]->id());
  const auto culled = recent.cull(s.kf[3]->id());
  EXPECT_EQ(culled.lines, 1);
  EXPECT_TRUE(two->is_bad());
  EXPECT_FALSE(three->is_bad());
  EXPECT_EQ(recent.lines_on_probation(), 1u);
}

TEST(LandmarkCulling, TheRulesFollowTheOptions) {
  FourKeyframes s;
  map::MapPoint* good = s.m.observe_point(s.kf[1], 1);
  s.m.observe_point(s.kf[2], 1);
  map::MapPoint* seen_half = s.m.observe_point(s.kf[1], 3);
  s.m.observe_point(s.kf[2], 3);
  s.m.observe_point(s.kf[3], 3);
  seen_half->increase_visible(1);  // found 1 of 2
  RecentLandmarkOptions o;
  o.min_point_weight = 6;    // three stereo keyframes
  o.min_found_ratio = 0.6;
  o.probation_keyframes = 1;
  RecentLandmarks recent(o);
  recent.add(good, s.kf[1]->id());
  recent.add(seen_half, s.kf[1]->id());
  EXPECT_EQ(recent.cull(s.kf[2]->id()).points, 2);
  EXPECT_TRUE(good->is_bad());
  EXPECT_TRUE(seen_half->is_bad());
}

}  // namespace landmark_culling_test
}  // namespace plslam::mapping
