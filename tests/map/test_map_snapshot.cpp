#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "plslam/map/map.h"
#include "plslam/map/map_snapshot.h"

namespace plslam::map {
namespace {

std::shared_ptr<FrameData> snapshot_frame_data(long id, double t) {
  auto d = std::make_shared<FrameData>();
  d->frame_id = id;
  d->timestamp = t;
  d->calib.width = 640;
  d->calib.height = 480;
  d->calib.fx = d->calib.fy = 500;
  d->calib.cx = 320;
  d->calib.cy = 240;
  d->calib.baseline = 0.1;
  d->descriptors = cv::Mat(0, 32, CV_8U);
  d->line_descriptors = cv::Mat(0, 32, CV_8U);
  d->build_grid();
  return d;
}

TEST(MapSnapshot, CopiesTheActiveObjectsWithTheirGeometry) {
  Map map;
  const geometry::SE3 T_cw0(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3));
  auto* k0 = map.create_keyframe(snapshot_frame_data(0, 10.0), T_cw0);
  auto* k1 = map.create_keyframe(snapshot_frame_data(5, 10.5), geometry::SE3());
  k1->change_parent(k0);
  k1->add_loop_edge(k0);
  auto* p0 = map.create_point(Eigen::Vector3d(1, 0, 5), k0, 0);
  auto* p1 = map.create_point(Eigen::Vector3d(-1, 0, 6), k0, 0);
  map.create_line(Eigen::Vector3d(0, 0, 4), Eigen::Vector3d(0, 1, 4), k1, 5);
  map.erase_point(p0);
  p1->set_position(Eigen::Vector3d(-1, 0.5, 6));

  const auto s = take_snapshot(map);
  ASSERT_EQ(s.keyframes.size(), 2u);
  EXPECT_EQ(s.keyframes[0].id, k0->id());
  EXPECT_DOUBLE_EQ(s.keyframes[0].timestamp, 10.0);
  EXPECT_TRUE(s.keyframes[0].T_wc.translation().isApprox(Eigen::Vector3d(-1, -2, -3)));
  EXPECT_EQ(s.keyframes[0].parent, -1);
  EXPECT_EQ(s.keyframes[1].parent, k0->id());
  ASSERT_EQ(s.keyframes[1].loop_edges.size(), 1u);
  EXPECT_EQ(s.keyframes[1].loop_edges[0], k0->id());
  // The erased point is gone; the moved one is where it was moved to.
  ASSERT_EQ(s.points.size(), 1u);
  EXPECT_EQ(s.points[0].id, p1->id());
  EXPECT_EQ(s.points[0].position, Eigen::Vector3d(-1, 0.5, 6));
  ASSERT_EQ(s.lines.size(), 1u);
  EXPECT_EQ(s.lines[0].end, Eigen::Vector3d(0, 1, 4));
  EXPECT_EQ(s.changes, map.changes());
}

TEST(MapSnapshot, ChangeCounterCountsCreationErasureAndNotedChanges) {
  Map map;
  const long c0 = map.changes();
  auto* kf = map.create_keyframe(snapshot_frame_data(0, 0.0), geometry::SE3());
  EXPECT_EQ(map.changes(), c0 + 1);
  auto* p = map.create_point(Eigen::Vector3d(0, 0, 5), kf, 0);
  map.erase_point(p);
  EXPECT_EQ(map.changes(), c0 + 3);
  const auto s = take_snapshot(map);
  EXPECT_EQ(map.changes(), s.changes);  // taking a snapshot changes nothing
  map.note_change();                      // an optimisation wrote poses back
  EXPECT_NE(map.changes(), s.changes);
  const long before_big = map.changes();
  map.note_big_change();  // a loop correction is a change as well
  EXPECT_EQ(map.changes(), before_big + 1);
}

// A reader takes snapshots while a writer adds points and moves them under the update mutex, as
// local mapping does: every snapshot is consistent (each batch is seen whole or not at all).
TEST(MapSnapshotConcurrent, SnapshotsNeverSeeHalfAnUpdate) {
  Map map;
  auto* kf = map.create_keyframe(snapshot_frame_data(0, 0.0), geometry::SE3());
  constexpr int kBatches = 200, kBatch = 10;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int b = 0; b < kBatches; ++b) {
      std::lock_guard lock(map.update_mutex());
      for (int i = 0; i < kBatch; ++i) map.create_point(Eigen::Vector3d(b, i, 5), kf, b);
      for (auto* p : map.points()) p->set_position(p->position() + Eigen::Vector3d(0, 0, 1));
      map.note_change();
    }
    done = true;
  });
  int taken = 0;
  while (!done || taken == 0) {
    const auto s = take_snapshot(map);
    ++taken;
    ASSERT_EQ(s.points.size() % kBatch, 0u);
    // After batch b (0-based) is written, every point has moved once per batch since its own.
    const long batches = static_cast<long>(s.points.size() / kBatch);
    for (const auto& p : s.points) {
      const long own = static_cast<long>(std::lround(p.position.x()));
      ASSERT_DOUBLE_EQ(p.position.z(), 5.0 + static_cast<double>(batches - own));
    }
  }
  writer.join();
  EXPECT_GT(taken, 0);
  EXPECT_EQ(take_snapshot(map).points.size(), static_cast<std::size_t>(kBatches * kBatch));
}

}  // namespace
}  // namespace plslam::map
