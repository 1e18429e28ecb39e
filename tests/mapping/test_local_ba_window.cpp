// The local BA window (which keyframes are optimised, which fixed) and the write-back of its
// result, on keyframes whose shared points are known exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>

#include "plslam/core/imu.h"
#include "plslam/mapping/local_ba_window.h"
#include "support/synthetic_views.h"

namespace plslam::mapping {
namespace local_ba_window_test {

using test::camera_at;
using test::range;

// Five keyframes along x, 0.3 m apart, and four groups of 20 points at 3 m:
//   A seen by 0 and 1, B by 1, 2 and 3, C by 2 and 3, D by 0 and 4.
// Covisibility: 3-2 (B + C), 3-1 (B), 2-1 (B), 1-0 (A), 0-4 (D).
struct Chain {
  test::SyntheticMap m;
  std::vector<map::KeyFrame*> kf;
  std::vector<int> A = range(0, 20), B = range(20, 20), C = range(40, 20), D = range(60, 20);
  Chain() {
    for (int i = 0; i < 80; ++i) m.world.add_point({-0.4 + 0.02 * i, -0.3 + 0.0075 * i, 3.0 + 0.01 * (i % 7)});
    for (int k = 0; k < 5; ++k) kf.push_back(m.add_keyframe(camera_at({0.3 * k, 0, 0})));
  }
  void connect() {
    m.observe_points(kf[0], join({A, D}));
    m.observe_points(kf[1], join({A, B}));
    m.observe_points(kf[2], join({B, C}));
    m.observe_points(kf[3], join({B, C}));
    m.observe_points(kf[4], D);
  }
  static std::vector<int> join(std::initializer_list<std::vector<int>> parts) {
    std::vector<int> out;
    for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
    return out;
  }
};

// keyframe -> fixed, for every keyframe of the window.
std::map<map::KeyFrame*, bool> fixed_flags(const MapBaProblem& w) {
  std::map<map::KeyFrame*, bool> out;
  for (std::size_t i = 0; i < w.keyframes.size(); ++i) out[w.keyframes[i]] = w.problem.keyframes[i].fixed;
  return out;
}

TEST(LocalBaWindow, OptimisesTheCovisiblesAndFixesTheOtherObservers) {
  Chain c;
  c.connect();
  ASSERT_EQ(c.kf[3]->covisibles(), (std::vector<map::KeyFrame*>{c.kf[2], c.kf[1]}));
  const MapBaProblem w = local_ba_window(*c.kf[3], LocalBaOptions{});
  // 3, 2 and 1 are optimised; 0 sees A (a landmark of 1) and is fixed; 4 sees none of them.
  EXPECT_EQ(fixed_flags(w), (std::map<map::KeyFrame*, bool>{
                                {c.kf[0], true}, {c.kf[1], false}, {c.kf[2], false}, {c.kf[3], false}}));
  EXPECT_EQ(w.points.size(), 60u);  // A, B and C
  EXPECT_EQ(std::count_if(w.points.begin(), w.points.end(), [&](auto* p) { return p == c.m.point[c.D[0]]; }), 0);
  // One observation per (point, observer): A 2, B 3, C 2.
  EXPECT_EQ(w.problem.point_observations.size(), 20u * (2 + 3 + 2));
}

TEST(LocalBaWindow, TheOriginStaysFixedInsideTheWindow) {
  Chain c;
  c.connect();
  const MapBaProblem w = local_ba_window(*c.kf[1], LocalBaOptions{});
  // 1's covisibles 0, 2, 3 are in the window, but 0 is the map's origin; 4 sees D through 0.
  EXPECT_EQ(fixed_flags(w), (std::map<map::KeyFrame*, bool>{
                                {c.kf[0], true}, {c.kf[1], false}, {c.kf[2], false}, {c.kf[3], false}, {c.kf[4], true}}));
  EXPECT_EQ(w.points.size(), 80u);
}

// A BA that covers keyframes mapped before it in one go optimises them too, covisible or not.
TEST(LocalBaWindow, AlsoFreeKeyframesAreOptimisedWithTheirLandmarks) {
  Chain c;
  c.connect();
  const MapBaProblem w = local_ba_window(*c.kf[3], LocalBaOptions{}, {c.kf[4], c.kf[3]});
  // 4 (not a covisible of 3) joins free with D, which 0 sees too (fixed: the origin); 3 once.
  EXPECT_EQ(fixed_flags(w), (std::map<map::KeyFrame*, bool>{{c.kf[0], true},
                                                            {c.kf[1], false},
                                                            {c.kf[2], false},
                                                            {c.kf[3], false},
                                                            {c.kf[4], false}}));
  EXPECT_EQ(w.points.size(), 80u);
}

// Keyframe 3 takes B's first point for C's 10th keypoint, a wrong association, and does not
// observe C's 10th point.
void connect_with_a_wrong_association(Chain& c, map::MapPoint** wrong, int* wrong_index) {
  c.m.observe_points(c.kf[0], Chain::join({c.A, c.D}));
  c.m.observe_points(c.kf[1], Chain::join({c.A, c.B}));
  c.m.observe_points(c.kf[2], Chain::join({c.B, c.C}));
  for (int w : Chain::join({c.B, c.C})) {
    if (w != c.B[0] && w != c.C[10]) c.m.observe_point(c.kf[3], w);
  }
  *wrong = c.m.point[c.B[0]];
  *wrong_index = c.m.keypoint_of(c.kf[3], c.C[10]);
  (*wrong)->add_observation(c.kf[3], *wrong_index);
  c.kf[3]->add_map_point(*wrong, *wrong_index);
  c.kf[3]->update_connections();
  c.m.observe_points(c.kf[4], c.D);
}

TEST(LocalBaWindow, WritesBackTheResultAndDropsOutlierObservations) {
  Chain c;
  map::MapPoint* wrong = nullptr;
  int wrong_index = -1;
  connect_with_a_wrong_association(c, &wrong, &wrong_index);
  const MapBaProblem w = local_ba_window(*c.kf[3], LocalBaOptions{});
  optim::BaOptions ba;
  ba.iterations = 5;
  ba.second_pass_iterations = 10;
  const auto result = optim::local_bundle_adjustment(geometry::StereoCamera(c.m.world.calib), w.problem, ba);
  ASSERT_TRUE(result.usable);
  std::vector<geometry::SE3> before;
  for (auto* k : w.keyframes) before.push_back(k->pose());
  write_back_local_ba(w, result);

  for (std::size_t i = 0; i < w.keyframes.size(); ++i) {
    const geometry::SE3 expected = w.problem.keyframes[i].fixed ? before[i] : result.poses[i].normalized();
    EXPECT_LT((w.keyframes[i]->pose().matrix() - expected.matrix()).norm(), 1e-12) << "keyframe " << i;
  }
  // Each observation flagged an outlier is gone from both sides, the others stay.
  int flagged = 0;
  for (std::size_t o = 0; o < w.point_observers.size(); ++o) {
    map::MapPoint* p = w.points[static_cast<std::size_t>(w.problem.point_observations[o].point)];
    map::KeyFrame* k = w.point_observers[o];
    if (result.point_observation_outlier[o]) {
      ++flagged;
      EXPECT_EQ(p->index_in(k), -1);
      const auto held = k->map_points();
      EXPECT_EQ(std::count(held.begin(), held.end(), p), 0);
    } else if (!p->is_bad()) {
      EXPECT_GE(p->index_in(k), 0);
    }
  }
  // The wrong one among them. (The solver drags the point in depth, where two keyframes 0.3 m
  // apart hold it weakly, so its true observations may go too: then it is bad.)
  EXPECT_GE(flagged, 1);
  EXPECT_EQ(wrong->index_in(c.kf[3]), -1);
  EXPECT_EQ(c.kf[3]->map_point(wrong_index), nullptr);
  int good = 0;
  for (std::size_t p = 0; p < w.points.size(); ++p) {
    if (w.points[p]->is_bad()) continue;
    ++good;
    EXPECT_EQ(w.points[p]->position(), result.points[p]);
  }
  EXPECT_GE(good, 59);
}

TEST(LocalBaWindow, MovesAPerturbedKeyframeBackAndLeavesTheFixedOnes) {
  Chain c;
  c.connect();
  const geometry::SE3 truth2 = c.kf[2]->pose();
  const geometry::SE3 pose0 = c.kf[0]->pose();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.002, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  c.kf[2]->set_pose(geometry::SE3(turn, Eigen::Vector3d(0.005, -0.004, 0.003)) * truth2);
  ASSERT_TRUE(run_local_ba(c.m.map, *c.kf[3], LocalBaOptions{}));
  EXPECT_LT((c.kf[2]->camera_center() - truth2.inverse().translation()).norm(), 1e-4);
  EXPECT_LT((c.kf[2]->pose().rotation() - truth2.rotation()).norm(), 1e-4);
  EXPECT_EQ(c.kf[0]->pose().matrix(), pose0.matrix());  // fixed: untouched
  for (int w : Chain::join({c.A, c.B, c.C})) {
    EXPECT_LT((c.m.point[w]->position() - c.m.world.points[static_cast<std::size_t>(w)]).norm(), 1e-4) << w;
    EXPECT_EQ(c.m.point[w]->num_observations(), w < 20 || w >= 40 ? 2 : 3);  // no observation lost
  }
}

// The abort seam: a flag raised before the solver's first iteration leaves the state where it
// started, and the result, written back all the same, says it was cut short.
TEST(LocalBaWindow, AnAbortRaisedBeforeTheFirstIterationWritesBackTheStartAndSaysSo) {
  Chain c;
  c.connect();
  const geometry::SE3 truth2 = c.kf[2]->pose();
  const geometry::SE3 perturbed = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.002, 0, 0)) * truth2;
  c.kf[2]->set_pose(perturbed);
  const std::atomic<bool> abort{true};
  bool aborted = false;
  ASSERT_TRUE(run_local_ba(c.m.map, *c.kf[3], LocalBaOptions{}, &abort, &aborted));
  EXPECT_TRUE(aborted);
  EXPECT_EQ(c.kf[2]->pose().matrix(), perturbed.matrix());

  const std::atomic<bool> go_on{false};
  ASSERT_TRUE(run_local_ba(c.m.map, *c.kf[3], LocalBaOptions{}, &go_on, &aborted));
  EXPECT_FALSE(aborted);
  EXPECT_LT((c.kf[2]->camera_center() - truth2.inverse().translation()).norm(), 1e-4);
}

TEST(LocalBaWindow, NothingToOptimiseWithoutObservations) {
  Chain c;  // keyframes without map points
  EXPECT_FALSE(run_local_ba(c.m.map, *c.kf[3], LocalBaOptions{}));
}

// A keyframe mapped after a black-out shares no landmark with the keyframe before it in time: once
// the IMU chain of the window no longer reaches back to it, its IMU factor still ties it (with the
// keyframe before it fixed) to the map before the gap. One that shares landmarks needs no such tie.
TEST(LocalBaWindow, AKeyframeTiedToTheOneBeforeItByTheImuAloneKeepsThatFactor) {
  for (const bool seen_across_the_gap : {false, true}) {
    SCOPED_TRACE(seen_across_the_gap ? "2 sees A too" : "the black-out between 1 and 2");
    Chain c;
    c.m.observe_points(c.kf[0], c.A);
    c.m.observe_points(c.kf[1], c.A);
    c.m.observe_points(c.kf[2], seen_across_the_gap ? Chain::join({c.A, c.B}) : c.B);
    c.m.observe_points(c.kf[3], Chain::join({c.B, c.C}));
    c.m.observe_points(c.kf[4], c.C);
    // At rest for 1 s, each keyframe 0.2 s after the one before it.
    std::vector<ImuSample> samples;
    for (int i = 0; i <= 200; ++i) samples.push_back({0.005 * i, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)});
    c.kf[0]->set_imu({});
    for (int k = 1; k < 5; ++k) {
      auto pim = std::make_shared<const inertial::Preintegration>(samples, 0.2 * (k - 1), 0.2 * k, inertial::ImuBias{},
                                                                  kEurocAdis16448Noise);
      c.kf[k]->set_imu({Eigen::Vector3d::Zero(), {}, c.kf[k - 1], pim});
    }
    LocalBaOptions o;
    o.imu_window = 1;  // the chain is 3 alone: its factor from 2
    const MapBaProblem w = local_ba_window(*c.kf[3], o);
    // 3 and its covisibles 2 and 4 are free; 1 is fixed: the IMU's tie to 2, or an observer of A.
    std::map<map::KeyFrame*, bool> expected{{c.kf[1], true}, {c.kf[2], false}, {c.kf[3], false}, {c.kf[4], false}};
    if (seen_across_the_gap) expected[c.kf[0]] = true;  // sees A too
    EXPECT_EQ(fixed_flags(w), expected);
    // 2 -> 3, and 1 -> 2 where the IMU alone ties 2 to 1 (4 shares C with 3: no factor of its own).
    EXPECT_EQ(w.problem.keyframe_factors.size(), seen_across_the_gap ? 1u : 2u);
  }
}

}  // namespace local_ba_window_test
}  // namespace plslam::mapping
