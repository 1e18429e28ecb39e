// Fusion of duplicate map points between a keyframe and its covisible neighbour.
#include <gtest/gtest.h>

#include "plslam/mapping/landmark_fusion.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace landmark_fusion_test {

using test::camera_at;
using test::range;

TEST(LandmarkFusion, MergesDuplicatesAndAddsMissedObservations) {
  // 40 points at 3 m seen by keyframes 0.2 m apart. Points 0-19 are one map point each, seen by
  // both; 20-29 have a map point in each keyframe (duplicates); 30-39 only in keyframe 1, while
  // keyframe 0's keypoint of them is free.
  test::SyntheticMap m;
  for (int i = 0; i < 40; ++i) m.world.add_point({-0.8 + 0.04 * i, -0.4 + 0.02 * (i % 20), 3.0});
  map::KeyFrame* k0 = m.add_keyframe(camera_at({0, 0, 0}));
  map::KeyFrame* k1 = m.add_keyframe(camera_at({0.2, 0, 0}));
  m.observe_points(k0, range(0, 30));
  m.observe_points(k1, range(0, 20));
  std::map<int, map::MapPoint*> own;  // keyframe 1's map point of each of 20-39
  for (int w = 20; w < 40; ++w) {
    const int i = m.keypoint_of(k1, w);
    map::MapPoint* p = m.map.create_point(m.world.points[static_cast<std::size_t>(w)], k1, k1->frame_id());
    p->add_observation(k1, i);
    k1->add_map_point(p, i);
    p->update_descriptor();
    p->update_normal_and_depth();
    own[w] = p;
  }
  k1->update_connections();
  ASSERT_EQ(k1->best_covisibles(10), std::vector<map::KeyFrame*>{k0});

  EXPECT_EQ(fuse_landmarks(*k1, FusionOptions{}), 10);
  for (int w = 0; w < 40; ++w) {
    map::MapPoint* in0 = k0->map_point(m.keypoint_of(k0, w));
    map::MapPoint* in1 = k1->map_point(m.keypoint_of(k1, w));
    ASSERT_NE(in0, nullptr) << w;
    EXPECT_EQ(in0, in1) << w;
    EXPECT_EQ(in0->num_observations(), 2) << w;
  }
  for (int w = 20; w < 30; ++w) {
    // Equally observed: keyframe 0's copy hands its observation over to keyframe 1's.
    EXPECT_TRUE(m.point[w]->is_bad());
    EXPECT_EQ(m.point[w]->replaced_by(), own[w]);
  }
  for (int w = 30; w < 40; ++w) EXPECT_EQ(own[w]->index_in(k0), m.keypoint_of(k0, w));
}

TEST(LandmarkFusion, TheMoreObservedCopySurvives) {
  // Point 20 is one map point for keyframes 0 and 2, and another for keyframe 1.
  test::SyntheticMap m;
  for (int i = 0; i < 21; ++i) m.world.add_point({-0.8 + 0.08 * i, 0.1, 3.0});
  map::KeyFrame* k0 = m.add_keyframe(camera_at({0, 0, 0}));
  map::KeyFrame* k1 = m.add_keyframe(camera_at({0.2, 0, 0}));
  map::KeyFrame* k2 = m.add_keyframe(camera_at({0.4, 0, 0}));
  m.observe_points(k0, range(0, 21));
  m.observe_points(k2, range(0, 21));
  m.observe_points(k1, range(0, 20));
  const int i = m.keypoint_of(k1, 20);
  map::MapPoint* copy = m.map.create_point(m.world.points[20], k1, k1->frame_id());
  copy->add_observation(k1, i);
  k1->add_map_point(copy, i);
  copy->update_descriptor();
  copy->update_normal_and_depth();

  EXPECT_EQ(fuse_landmarks(*k1, FusionOptions{}), 1);
  EXPECT_TRUE(copy->is_bad());
  EXPECT_EQ(copy->replaced_by(), m.point[20]);
  EXPECT_EQ(k1->map_point(i), m.point[20]);
  EXPECT_EQ(m.point[20]->num_observations(), 3);
}

}  // namespace landmark_fusion_test
}  // namespace plslam::mapping
