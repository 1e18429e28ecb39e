#pragma once
// The map: owner of every keyframe, map point and map line. Culled objects are flagged bad and
// leave the active sets. Keyframes live as long as the Map (a culled keyframe still anchors the
// poses of the frames tracked against it). Culled points and lines are freed by reclaim(), which
// the caller runs only at a point where no thread can hold a pointer to them (see reclaim()).
// Thread-safe.
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <shared_mutex>
#include <vector>

#include "plslam/map/keyframe.h"
#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::map {

class Map {
 public:
  Map() = default;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  // `segment`: the map segment whose frame T_cw is in (start_segment()).
  KeyFrame* create_keyframe(std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw, int segment = 0);
  MapPoint* create_point(const Eigen::Vector3d& position, KeyFrame* reference, long frame_id);
  MapLine* create_line(const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                       long frame_id);

  // Objects read from a map file keep their saved ids (system/map_file); an id already in use
  // throws std::invalid_argument. The next ids are restored as saved, so that objects created
  // after loading never reuse an id.
  KeyFrame* restore_keyframe(long id, std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw);
  MapPoint* restore_point(long id, const Eigen::Vector3d& position, KeyFrame* reference, long frame_id);
  MapLine* restore_line(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                        long frame_id);
  struct NextIds {
    long keyframe = 0, point = 0, line = 0;
  };
  NextIds next_ids() const;
  void restore_next_ids(const NextIds& next);

  // Removes from the active set (a keyframe stays alive until the Map is destroyed).
  void erase_keyframe(KeyFrame* kf);
  // Culls (set_bad()) and removes from the active set; reclaim() frees it later.
  void erase_point(MapPoint* p);
  void erase_line(MapLine* l);

  // Frees every bad point and line. Call it only where no thread can hold a pointer to a bad
  // one: tracking at a frame boundary, local mapping and loop closing idle and held paused, no
  // global BA running (System::reclaim_culled). Set_bad() has cleared the keyframes' slots, so
  // the only pointers left are those the threads keep across steps (the tracker's last frame,
  // local mapping's probation list): `drop_bad` runs first, under the same lock, and must clear
  // them. Snapshot readers in other threads hold hold_objects() while they read.
  struct Reclaimed {
    int points = 0, lines = 0;
  };
  Reclaimed reclaim(const std::function<void()>& drop_bad = {});
  // While held, reclaim() waits: for readers outside the SLAM threads (snapshots, map writers).
  std::shared_lock<std::shared_mutex> hold_objects() const { return std::shared_lock(objects_mutex_); }
  // Totals freed so far.
  Reclaimed reclaimed() const;

  // Re-expresses the whole map in another world frame: x_new = T_new_old x_old for every keyframe
  // (culled ones too: they still anchor frames), point, line and viewing direction (a gravity-
  // aligned world once the IMU is initialised, system/slam_system). Holds update_mutex(); call it
  // where no other thread writes the map (as reclaim()); whoever keeps a world pose across frames
  // (the tracker) re-expresses it too.
  void transform_world(const geometry::SE3& T_new_old);

  std::vector<KeyFrame*> keyframes() const;  // active, by id
  std::vector<MapPoint*> points() const;
  std::vector<MapLine*> lines() const;
  std::size_t num_keyframes() const;
  std::size_t num_points() const;
  std::size_t num_lines() const;
  // The active sets' sizes without filtering them: objects turned bad since the last access or
  // reclaim() are still counted. For logs (frames.csv), where num_points()'s O(n) copy is waste.
  struct Sizes {
    std::size_t keyframes = 0, points = 0, lines = 0;
  };
  Sizes sizes() const;
  // The first keyframe created or restored: the origin (KeyFrame::is_origin()), whatever its id.
  KeyFrame* first_keyframe() const;

  // Map segments. A lost camera that cannot relocalize starts a new, disconnected segment whose
  // frame is only the motion model's guess of where the camera went. Segment 0 (the first map, or
  // a loaded one) is anchored: its frame is the map's. Another segment is anchored once a loop ties
  // it to an anchored one; until then its poses are right relative to each other only.
  int start_segment();                 // a new, unanchored segment's number
  void tie_segments(int a, int b);     // a loop between keyframes of segments a and b
  bool anchored(int segment) const;
  int num_segments() const;

  // Held by whoever changes poses or structure wholesale (local BA write-back) and by tracking
  // while it reads them, so that tracking never sees half an update (ORB-SLAM2's mMutexMapUpdate).
  std::mutex& update_mutex() const { return update_mutex_; }
  // Counts wholesale changes of the map's geometry (a loop correction, a global BA merge): every
  // keyframe may have moved, so whoever keeps a pose across frames (the tracker's last frame)
  // re-expresses it through its reference keyframe when the count changed.
  long big_changes() const { return big_changes_.load(); }
  void note_big_change() {
    ++big_changes_;
    ++changes_;
  }
  // Counts every change a reader outside the SLAM threads may want to redraw or rewrite: objects
  // created, restored or erased, poses and positions moved by an optimisation (note_change() by
  // whoever writes them back), and the big changes. A viewer takes a new snapshot
  // (map/map_snapshot.h) only when it differs from the snapshot's.
  long changes() const { return changes_.load(); }
  void note_change() { ++changes_; }

 private:
  mutable std::mutex mutex_;
  mutable std::mutex update_mutex_;
  mutable std::shared_mutex objects_mutex_;  // exclusive in reclaim()
  std::atomic<long> big_changes_{0};
  std::atomic<long> changes_{0};
  std::vector<std::unique_ptr<KeyFrame>> all_keyframes_;
  // Points and lines until freed by reclaim(), in creation order.
  std::vector<std::unique_ptr<MapPoint>> all_points_;
  std::vector<std::unique_ptr<MapLine>> all_lines_;
  Reclaimed reclaimed_;  // guarded by mutex_
  mutable IdSet<KeyFrame> keyframes_;
  mutable IdSet<MapPoint> points_;
  mutable IdSet<MapLine> lines_;
  long next_keyframe_id_ = 0, next_point_id_ = 0, next_line_id_ = 0;
  // Union-find over segments (guarded by mutex_): segment_parent_[s] == s at a root, and a root
  // is anchored when its set holds segment 0.
  std::vector<int> segment_parent_{0};
  int segment_root(int s) const;
};

}  // namespace plslam::map
