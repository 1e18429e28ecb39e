// Redundant keyframe culling on keyframes whose shared points are known exactly.
#include <gtest/gtest.h>

#include "plslam/mapping/keyframe_culling.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace keyframe_culling_test {

using test::camera_at;
using test::range;

// Keyframes 0.1 m apart sideways, looking at 20 close points (3 m, under 40 baselines = 4 m) and
// 10 far ones (10 m).
struct Row {
  test::SyntheticMap m;
  std::vector<int> close = range(0, 20), far = range(20, 10);
  Row() {
    for (int i = 0; i < 20; ++i) m.world.add_point({-0.8 + 0.08 * i, -0.4 + 0.04 * i, 3.0});
    for (int i = 0; i < 10; ++i) m.world.add_point({-2.0 + 0.4 * i, 0.5, 10.0});
  }
  map::KeyFrame* add(int k, const std::vector<int>& observed) {
    map::KeyFrame* kf = m.add_keyframe(camera_at({0.1 * k, 0, 0}));
    m.observe_points(kf, observed);
    return kf;
  }
};

TEST(KeyframeCulling, RedundantWhenMoreThan90PercentOfItsClosePointsAreSeenByThreeOthers) {
  for (const int shared : {18, 19}) {  // 90 % exactly is not redundant; 95 % is
    Row r;
    map::KeyFrame* k = r.add(0, r.close);
    for (int o = 1; o <= 3; ++o) r.add(o, range(0, shared));
    EXPECT_EQ(is_redundant(*k, KeyframeCullingOptions{}), shared == 19) << shared << " of 20 shared";
  }
}

TEST(KeyframeCulling, TwoOtherObserversAreNotEnough) {
  Row r;
  map::KeyFrame* k = r.add(0, r.close);
  r.add(1, r.close);
  r.add(2, r.close);
  EXPECT_FALSE(is_redundant(*k, KeyframeCullingOptions{}));
  KeyframeCullingOptions two;
  two.observers = 2;
  EXPECT_TRUE(is_redundant(*k, two));
}

TEST(KeyframeCulling, OnlyClosePointsCount) {
  // 20 close points seen by three others, 10 far ones by nobody else: redundant, unless the far
  // ones count as close (then 20 of 30).
  Row r;
  std::vector<int> all = r.close;
  all.insert(all.end(), r.far.begin(), r.far.end());
  map::KeyFrame* k = r.add(0, all);
  for (int o = 1; o <= 3; ++o) r.add(o, r.close);
  EXPECT_TRUE(is_redundant(*k, KeyframeCullingOptions{}));
  KeyframeCullingOptions wide;
  wide.close_depth_baselines = 200;  // 20 m
  EXPECT_FALSE(is_redundant(*k, wide));
}

TEST(KeyframeCulling, OthersMustSeeThePointAtTheSameOrAFinerScale) {
  Row r;
  map::KeyFrame* k = r.add(0, r.close);
  for (int o = 1; o <= 3; ++o) {
    map::KeyFrame* coarse = r.m.add_keyframe(camera_at({0.1 * o, 0, 0}), true, std::nullopt, 2);  // octave 2
    r.m.observe_points(coarse, r.close);
  }
  EXPECT_FALSE(is_redundant(*k, KeyframeCullingOptions{}));
}

TEST(KeyframeCulling, CullsTheRedundantCovisiblesButNeverTheOriginNorALoopKeyframe) {
  // Five keyframes see the same 20 close points. From keyframe 4: keyframe 0 is the origin and
  // stays although redundant; keyframe 1 goes (0, 2, 3 and 4 see its points); then keyframe 2 has
  // only 0, 3 and 4 left... which is still three: it goes too; keyframe 3 is left with 0 and 4.
  Row r;
  std::vector<map::KeyFrame*> kf;
  for (int k = 0; k < 5; ++k) kf.push_back(r.add(k, r.close));
  ASSERT_TRUE(kf[0]->is_origin());
  ASSERT_TRUE(is_redundant(*kf[0], KeyframeCullingOptions{}));
  std::vector<map::KeyFrame*> reported;
  const auto culled = cull_redundant_keyframes(r.m.map, *kf[4], KeyframeCullingOptions{},
                                               [&](map::KeyFrame* k) { reported.push_back(k); });
  EXPECT_EQ(culled, (std::vector<map::KeyFrame*>{kf[1], kf[2]}));
  EXPECT_EQ(reported, culled);
  EXPECT_FALSE(kf[0]->is_bad());
  EXPECT_TRUE(kf[1]->is_bad());
  EXPECT_TRUE(kf[2]->is_bad());
  EXPECT_FALSE(kf[3]->is_bad());
  EXPECT_EQ(r.m.map.num_keyframes(), 3u);

  // With a loop edge keyframe 1 stays, and 2 and 3 (each still seen by three others) go.
  Row loop;
  std::vector<map::KeyFrame*> lk;
  for (int k = 0; k < 5; ++k) lk.push_back(loop.add(k, loop.close));
  lk[1]->add_loop_edge(lk[0]);
  const auto culled_loop = cull_redundant_keyframes(loop.m.map, *lk[4], KeyframeCullingOptions{});
  EXPECT_EQ(culled_loop, (std::vector<map::KeyFrame*>{lk[2], lk[3]}));
  EXPECT_FALSE(lk[1]->is_bad());
}

// A keyframe of the IMU chain is culled only when its neighbours' interval stays short, and never
// the chain's last (tracking predicts from it); one outside a chain as before.
TEST(KeyframeCulling, TheImuChainKeepsItsIntervalsShort) {
  Row r;
  map::KeyFrame* k[4];
  for (int i = 0; i < 4; ++i) k[i] = r.add(i, r.close);
  KeyframeCullingOptions o;
  EXPECT_TRUE(imu_chain_allows_culling(*k[1], o));  // no IMU state
  // The keyframes are 0.05 s apart: the limit is set from their spacing.
  k[0]->set_imu({});
  k[1]->set_imu({Eigen::Vector3d::Zero(), {}, k[0], nullptr});
  k[2]->set_imu({Eigen::Vector3d::Zero(), {}, k[1], nullptr});
  o.max_imu_interval_s = k[2]->timestamp() - k[0]->timestamp();
  EXPECT_TRUE(imu_chain_allows_culling(*k[1], o));   // its neighbours just within the limit
  EXPECT_TRUE(imu_chain_allows_culling(*k[0], o));   // the chain's first: its successor starts it
  EXPECT_FALSE(imu_chain_allows_culling(*k[2], o));  // the chain's last
  o.max_imu_interval_s *= 0.99;
  EXPECT_FALSE(imu_chain_allows_culling(*k[1], o));
}

}  // namespace keyframe_culling_test
}  // namespace plslam::mapping
