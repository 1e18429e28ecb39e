// The Tracker on frames with exact ground truth (support/synthetic_views.h): it starts a map from
// a stereo frame, follows known small motions to within 1e-5, says LOST when the image content
// disappears, and without place recognition starts a new map segment when it comes back.
#include <gtest/gtest.h>

#include <random>

#include "plslam/tracking/tracker.h"
#include "support/synthetic_views.h"

namespace plslam::tracking {
namespace tracker_test {

// 1200 points spread over the first camera's image, 2 to 15 m deep (uniform in inverse depth).
test::SyntheticWorld scene(int points = 1200) {
  test::SyntheticWorld w;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(10, 630), v(10, 470), inv_z(1 / 15.0, 1 / 2.0);
  for (int i = 0; i < points; ++i) w.add_point_seen_at(geometry::SE3(), {u(rng), v(rng)}, 1 / inv_z(rng));
  return w;
}

// T_cw of frame k of a camera moving 2 cm forward, 1 cm right and turning 0.3 degrees left per
// frame (20 Hz): a walking pace.
geometry::SE3 walk(int k) {
  const geometry::SE3 step(Eigen::AngleAxisd(-0.3 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                           Eigen::Vector3d(-0.01, 0, -0.02));
  geometry::SE3 T;
  for (int i = 0; i < k; ++i) T = step * T;
  return T;
}

double translation_error(const geometry::SE3& a, const geometry::SE3& b) {
  return (a.inverse().translation() - b.inverse().translation()).norm();
}
double rotation_error(const geometry::SE3& a, const geometry::SE3& b) {
  return Eigen::AngleAxisd(a.rotation() * b.rotation().transpose()).angle();
}

struct Rig {
  map::Map map;
  std::vector<map::KeyFrame*> inserted;
  Tracker tracker;
  explicit Rig(TrackerOptions o = {})
      : tracker(map, o, [this](map::KeyFrame* kf) { inserted.push_back(kf); }, [] { return true; }) {}
  geometry::SE3 last_pose() const { return Tracker::pose_of(tracker.records().back()); }
};

// A frame with nothing in it: a lens cap, a black-out.
std::shared_ptr<map::FrameData> blank_frame(long id) {
  auto d = std::make_shared<map::FrameData>();
  d->frame_id = id;
  d->timestamp = 0.05 * static_cast<double>(id);
  d->calib = test::small_calibration();
  d->descriptors = cv::Mat(0, 32, CV_8U);
  d->line_descriptors = cv::Mat(0, 32, CV_8U);
  d->build_grid();
  return d;
}

TEST(Tracker, StartsAMapFromTheFirstStereoFrame) {
  const auto world = scene();
  Rig rig;
  const auto view = world.observe(walk(0), 0);
  int stereo = 0;
  for (float z : view.data->depth) stereo += z > 0;
  ASSERT_GE(stereo, 500);

  const TrackResult r = rig.tracker.track(view.data);
  EXPECT_EQ(r.state, TrackingState::kOk);
  EXPECT_TRUE(r.tracked);
  EXPECT_TRUE(r.keyframe);
  ASSERT_EQ(rig.map.num_keyframes(), 1u);
  ASSERT_EQ(rig.inserted.size(), 1u);
  map::KeyFrame* kf = rig.inserted.front();
  EXPECT_TRUE(kf->is_origin());
  // One map point per stereo keypoint, where the world point is (float keypoints and depths).
  EXPECT_EQ(static_cast<int>(rig.map.num_points()), stereo);
  for (std::size_t i = 0; i < view.point_of.size(); ++i) {
    map::MapPoint* mp = kf->map_point(static_cast<int>(i));
    if (view.data->depth[i] <= 0) {
      EXPECT_EQ(mp, nullptr);
      continue;
    }
    ASSERT_NE(mp, nullptr);
    EXPECT_LT((mp->position() - world.points[static_cast<std::size_t>(view.point_of[i])]).norm(), 1e-5);
  }
  EXPECT_LT(translation_error(rig.last_pose(), walk(0)), 1e-12);
}

TEST(Tracker, NeedsEnoughStereoPointsToStart) {
  const auto world = scene(400);  // under init_min_points (500)
  Rig rig;
  const TrackResult r = rig.tracker.track(world.observe(walk(0), 0).data);
  EXPECT_EQ(r.state, TrackingState::kNotInitialized);
  EXPECT_FALSE(r.tracked);
  EXPECT_EQ(rig.map.num_keyframes(), 0u);
  EXPECT_TRUE(rig.inserted.empty());
}

TEST(Tracker, FollowsAKnownSmallMotion) {
  const auto world = scene();
  Rig rig;
  rig.tracker.track(world.observe(walk(0), 0).data);
  // Frame 1: no velocity yet, tracked against the reference keyframe. Frames 2-5: the motion model.
  for (int k = 1; k <= 5; ++k) {
    const TrackResult r = rig.tracker.track(world.observe(walk(k), k).data);
    ASSERT_TRUE(r.tracked) << "frame " << k;
    EXPECT_EQ(r.state, TrackingState::kOk);
    EXPECT_GT(r.point_inliers, 500) << "frame " << k;
    EXPECT_LT(translation_error(rig.last_pose(), walk(k)), 1e-5) << "frame " << k;
    EXPECT_LT(rotation_error(rig.last_pose(), walk(k)), 1e-5) << "frame " << k;
  }
  EXPECT_EQ(rig.tracker.lost_events(), 0);
}

TEST(Tracker, FollowsAKnownSmallMotionWithLinesToo) {
  auto world = scene();
  // 40 slanted segments, 3 to 8 m deep, spread over the first camera's image.
  const auto cam = world.camera();
  for (int i = 0; i < 40; ++i) {
    const double u = 60 + 13 * i, z = 3 + 0.125 * i;
    world.add_segment(cam.unproject({u, 80.0 + 3 * (i % 5)}, z), cam.unproject({u + 25, 400.0 - 4 * (i % 7)}, z + 0.3));
  }
  Rig rig;
  ASSERT_TRUE(rig.tracker.track(world.observe(walk(0), 0).data).tracked);
  EXPECT_EQ(rig.map.num_lines(), 40u);
  for (int k = 1; k <= 5; ++k) {
    const TrackResult r = rig.tracker.track(world.observe(walk(k), k).data);
    ASSERT_TRUE(r.tracked) << "frame " << k;
    EXPECT_GT(r.line_inliers, 30) << "frame " << k;
    EXPECT_LT(translation_error(rig.last_pose(), walk(k)), 1e-5) << "frame " << k;
    EXPECT_LT(rotation_error(rig.last_pose(), walk(k)), 1e-5) << "frame " << k;
  }
}

// A sudden turn with a sideways jump the motion model did not predict: 3 degrees of yaw and
// 0.6 m to the side move each point by 400 (0.6 / z - 0.052) px, so the 7 px windows keep only
// the far points (8.6-17 m deep): about a tenth of the last frame's matches, nearly all right. The
// few-matches rule searches again in the wide windows; without it (and with the inlier-share
// rule off) the motion model keeps the narrow attempt.
int wide_retries_on_a_sudden_turn(double min_match_share) {
  const auto world = scene();
  TrackerOptions o;
  o.motion_min_inlier_share = 0;
  o.motion_min_match_share = min_match_share;
  Rig rig(o);
  for (int k = 0; k <= 4; ++k) EXPECT_TRUE(rig.tracker.track(world.observe(walk(k), k).data).tracked);
  EXPECT_EQ(rig.tracker.motion_wide_retries(), 0);
  const geometry::SE3 jump(Eigen::AngleAxisd(3 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                           Eigen::Vector3d(-0.6, 0, 0));
  const geometry::SE3 truth = jump * walk(5);
  const TrackResult r = rig.tracker.track(world.observe(truth, 5).data);
  EXPECT_TRUE(r.tracked);
  EXPECT_LT(translation_error(rig.last_pose(), truth), 1e-4);
  return rig.tracker.motion_wide_retries();
}

TEST(Tracker, FewMotionMatchesForTheLastFramesPointsMeanASuddenTurnAndAWideSearch) {
  EXPECT_EQ(wide_retries_on_a_sudden_turn(0.3), 1);
  EXPECT_EQ(wide_retries_on_a_sudden_turn(0.0), 0);
}

// A pose far from the constant-velocity prediction is reported, never silently kept (issue 20):
// here the camera really jumps 0.6 m sideways, so the pose is right and stays; a look-alike
// place would look the same to this check. A 0.3 m jump is within the 0.5 m limit.
std::vector<SuspectJump> jumps_after_a_sideways_jump(double metres) {
  const auto world = scene();
  Rig rig;
  for (int k = 0; k <= 4; ++k) EXPECT_TRUE(rig.tracker.track(world.observe(walk(k), k).data).tracked);
  EXPECT_EQ(rig.tracker.motion_deviation_m().size(), 3u);  // frames 2-4 had a velocity
  for (double m : rig.tracker.motion_deviation_m()) EXPECT_LT(m, 1e-4);
  const geometry::SE3 truth = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-metres, 0, 0)) * walk(5);
  EXPECT_TRUE(rig.tracker.track(world.observe(truth, 5).data).tracked);
  EXPECT_LT(translation_error(rig.last_pose(), truth), 1e-4);
  EXPECT_NEAR(rig.tracker.motion_deviation_m().back(), metres, 1e-3);
  return rig.tracker.suspect_jumps();
}

TEST(Tracker, APoseFarFromThePredictionIsReportedAsASuspectJump) {
  const auto jumps = jumps_after_a_sideways_jump(0.6);
  ASSERT_EQ(jumps.size(), 1u);
  EXPECT_EQ(jumps[0].frame_id, 5);
  EXPECT_NEAR(jumps[0].deviation_m, 0.6, 1e-3);
  EXPECT_LT(jumps[0].deviation_deg, 1e-3);
  EXPECT_TRUE(jumps_after_a_sideways_jump(0.3).empty());
}

TEST(Tracker, ReportsLostWhenTheImageContentDisappears) {
  const auto world = scene();
  Rig rig;
  for (int k = 0; k <= 2; ++k) ASSERT_TRUE(rig.tracker.track(world.observe(walk(k), k).data).tracked);
  const TrackResult lost = rig.tracker.track(blank_frame(3));
  EXPECT_EQ(lost.state, TrackingState::kLost);
  EXPECT_FALSE(lost.tracked);
  EXPECT_FALSE(lost.keyframe);
  EXPECT_EQ(rig.tracker.lost_events(), 1);
  EXPECT_FALSE(rig.tracker.records().back().tracked);
  // Still nothing: still lost, and no second loss event.
  EXPECT_EQ(rig.tracker.track(blank_frame(4)).state, TrackingState::kLost);
  EXPECT_EQ(rig.tracker.lost_events(), 1);
}

TEST(Tracker, WithoutPlaceRecognitionALostCameraStartsANewMapSegment) {
  const auto world = scene();
  Rig rig;
  for (int k = 0; k <= 2; ++k) ASSERT_TRUE(rig.tracker.track(world.observe(walk(k), k).data).tracked);
  ASSERT_EQ(rig.tracker.track(blank_frame(3)).state, TrackingState::kLost);
  const TrackResult back = rig.tracker.track(world.observe(walk(4), 4).data);
  EXPECT_EQ(back.state, TrackingState::kOk);
  EXPECT_TRUE(back.new_map_segment);
  EXPECT_TRUE(back.keyframe);
  EXPECT_EQ(rig.tracker.new_segment_frames(), std::vector<long>{4});
  // The new segment's first keyframe is not the map's origin: that stays the first one.
  ASSERT_GE(rig.inserted.size(), 2u);
  EXPECT_TRUE(rig.inserted.front()->is_origin());
  EXPECT_FALSE(rig.inserted.back()->is_origin());
  EXPECT_EQ(rig.map.first_keyframe(), rig.inserted.front());
  // Its frames are right relative to each other, but where it lies is the motion model's guess
  // across the loss: unanchored, not trusted, until a loop ties it to the first segment.
  EXPECT_EQ(back.frame_state, FrameState::kUnanchored);
  EXPECT_FALSE(back.tracked);
  const int segment = rig.inserted.back()->segment();
  EXPECT_NE(segment, 0);
  const TrackResult next = rig.tracker.track(world.observe(walk(5), 5).data);
  EXPECT_EQ(next.frame_state, FrameState::kUnanchored);
  rig.tracker.settle_states();
  EXPECT_EQ(rig.tracker.records().back().state, FrameState::kUnanchored);
  rig.map.tie_segments(segment, 0);
  rig.tracker.settle_states();
  EXPECT_EQ(rig.tracker.records().back().state, FrameState::kTracked);
  EXPECT_EQ(rig.tracker.records()[4].state, FrameState::kTracked);
  EXPECT_EQ(rig.tracker.records()[3].state, FrameState::kLost);
}

}  // namespace tracker_test
}  // namespace plslam::tracking
