// One pose per input frame for index-paired formats: untracked frames hold the last tracked pose
// and are listed, so every tracked frame keeps its line.
#include <stdexcept>

#include <gtest/gtest.h>

#include "plslam/system/input_aligned_trajectory.h"

namespace plslam::system {
namespace {

tracking::FrameRecord record(long id, double x, bool tracked) {
  tracking::FrameRecord r;
  r.frame_id = id;
  r.timestamp = 0.1 * static_cast<double>(id);
  // No reference keyframe: T_cr is T_cw itself. Camera at x on the x axis: T_cw translation -x.
  r.T_cr = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-x, 0, 0));
  r.tracked = tracked;
  r.state = tracked ? tracking::FrameState::kTracked : tracking::FrameState::kLost;
  return r;
}

std::vector<double> times(std::size_t n) {
  std::vector<double> t;
  for (std::size_t i = 0; i < n; ++i) t.push_back(0.1 * static_cast<double>(i));
  return t;
}

TEST(InputAlignedTrajectory, OneLinePerInputFrameWithGapsHeld) {
  // Input 0..7: 0 before init (not tracked), 1-2 tracked, 3 skipped (no record), 4 tracked,
  // 5 lost (a prediction at x=99 that must not appear), 6 tracked, 7 not reached.
  const std::vector<tracking::FrameRecord> recs = {record(0, 50, false), record(1, 1, true), record(2, 2, true),
                                                   record(4, 4, true),   record(5, 99, false), record(6, 6, true)};
  const auto a = align_to_input(recs, times(8));
  ASSERT_EQ(a.poses.size(), 8u);
  const double expected_x[] = {1, 1, 2, 2, 4, 4, 6, 6};
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_NEAR(a.poses[i].T.translation().x(), expected_x[i], 1e-12) << i;
    EXPECT_DOUBLE_EQ(a.poses[i].t, 0.1 * static_cast<double>(i));
  }
  EXPECT_EQ(a.untracked, (std::vector<std::size_t>{0, 3, 5, 7}));
}

TEST(InputAlignedTrajectory, RecoveringFramesAreNotTrustedLines) {
  // 0 tracked, 1-2 recovering from a relocalization (poses, but not trusted), 3 relocalized.
  auto recs = std::vector<tracking::FrameRecord>{record(0, 0, true), record(1, 50, true), record(2, 51, true),
                                                 record(3, 3, true)};
  recs[1].state = recs[2].state = tracking::FrameState::kRecovering;
  recs[3].state = tracking::FrameState::kRelocalized;
  const auto a = align_to_input(recs, times(4));
  ASSERT_EQ(a.poses.size(), 4u);
  const double expected_x[] = {0, 0, 0, 3};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(a.poses[i].T.translation().x(), expected_x[i], 1e-12) << i;
  EXPECT_EQ(a.untracked, (std::vector<std::size_t>{1, 2}));
}

TEST(InputAlignedTrajectory, NothingTrackedGivesNoPoses) {
  const auto a = align_to_input({record(0, 0, false), record(1, 0, false)}, times(3));
  EXPECT_TRUE(a.poses.empty());
}

TEST(InputAlignedTrajectory, RecordOutsideTheInputIsABug) {
  EXPECT_THROW(align_to_input({record(5, 0, true)}, times(3)), std::logic_error);
}

}  // namespace
}  // namespace plslam::system
