#pragma once
// A keyframe: a frame kept in the map, with its pose, its associations to map points and lines,
// its covisibility edges (weighted by shared points and lines) and its place in the spanning tree.
// Owned by the Map; other objects hold non-owning pointers. Pose, associations and graph edges
// each have their own mutex because tracking, local mapping and (later) loop closing use them
// concurrently.
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/inertial/imu_bias.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/map/by_id.h"
#include "plslam/map/frame_data.h"

namespace plslam::map {

class MapPoint;
class MapLine;
class KeyFrame;

// What a keyframe of a visual-inertial map knows of the IMU (once it is initialised and the world
// gravity-aligned): the body's velocity and the biases at the keyframe, and the IMU's motion since
// the keyframe before it in time (the IMU chain, whose consecutive pairs local BA ties with IMU
// factors). No predecessor: the chain starts here.
struct KeyFrameImu {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  // world frame
  inertial::ImuBias bias;
  KeyFrame* previous = nullptr;
  std::shared_ptr<const inertial::Preintegration> from_previous;  // set with `previous`
  // v and bias are a visual-inertial BA's estimates; false: tracking's, or a seed from the
  // positions, until a local BA with this keyframe's IMU factors estimates them. Tracking's own
  // estimates, each made from the keyframe before held fixed, drift when no BA follows them (local
  // mapping falling behind), so tracking builds on estimated states only.
  bool estimated = false;
};

class KeyFrame {
 public:
  // `origin`: the map's first keyframe (Map::first_keyframe()), whatever its id. `segment`: the
  // map segment it was made in (Map::start_segment()).
  KeyFrame(long id, std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw, bool origin = false,
           int segment = 0);

  long id() const { return id_; }
  // The keyframe that holds the map's gauge: never culled, fixed in local and global BA. It is the
  // map's first keyframe, which need not have id 0 (a loaded map's first one is its lowest id).
  bool is_origin() const { return origin_; }
  // The map segment whose frame its pose is in (Map::anchored() tells whether that is the map's).
  int segment() const { return segment_; }
  const FrameData& data() const { return *data_; }
  const std::shared_ptr<const FrameData>& shared_data() const { return data_; }
  long frame_id() const { return data_->frame_id; }
  double timestamp() const { return data_->timestamp; }

  geometry::SE3 pose() const;  // T_cw
  geometry::SE3 pose_inverse() const;  // T_wc
  Eigen::Vector3d camera_center() const;
  void set_pose(const geometry::SE3& T_cw);
  // A correction that moves the keyframe with its surroundings (loop correction, global BA): its
  // IMU velocity turns as its camera does.
  void move_to(const geometry::SE3& T_cw);

  // Point associations, indexed like data().keypoints.
  void add_map_point(MapPoint* p, int index);
  void erase_map_point(int index);
  void erase_map_point(const MapPoint* p);
  MapPoint* map_point(int index) const;
  std::vector<MapPoint*> map_points() const;  // same size as keypoints; nullptr where none
  // Map points whose observation weight (a stereo observation counts 2) is at least min_obs:
  // ORB-SLAM2's TrackedMapPoints.
  int tracked_map_points(int min_obs) const;

  // Line associations, indexed like data().lines.
  void add_map_line(MapLine* l, int index);
  void erase_map_line(int index);
  void erase_map_line(const MapLine* l);
  MapLine* map_line(int index) const;
  std::vector<MapLine*> map_lines() const;
  int tracked_map_lines(int min_obs) const;

  // Covisibility: recomputes the weights to every keyframe sharing at least `min_shared` points
  // or lines (the strongest one is kept even below it), updates the other side's edges, and on
  // first call attaches this keyframe to the spanning tree under its strongest neighbour.
  void update_connections(int min_shared = 15);
  void add_connection(KeyFrame* kf, int weight);
  void erase_connection(KeyFrame* kf);
  std::vector<KeyFrame*> covisibles() const;                 // by decreasing weight
  std::vector<KeyFrame*> best_covisibles(std::size_t n) const;
  int weight(const KeyFrame* kf) const;

  // Spanning tree.
  KeyFrame* parent() const;
  IdSet<KeyFrame> children() const;
  void add_child(KeyFrame* kf);
  void erase_child(KeyFrame* kf);
  void change_parent(KeyFrame* kf);

  // Loop edges: keyframes this one was tied to by a closed loop. They stay in the essential graph
  // of every later loop, and local mapping never culls a keyframe that has one.
  void add_loop_edge(KeyFrame* kf);
  IdSet<KeyFrame> loop_edges() const;

  // A keyframe read from a map file: its covisibility weights, spanning-tree parent (null for a
  // root) and loop edges as saved. It counts as connected, so update_connections() never
  // re-attaches it to the tree.
  void restore_graph(KeyFrame* parent, const IdMap<KeyFrame, int>& weights, const IdSet<KeyFrame>& loop_edges);

  // The IMU state (nullopt: a keyframe of a visual-only map, or made before the initialisation).
  bool has_imu() const;
  std::optional<KeyFrameImu> imu() const;
  // Sets it and makes this keyframe its predecessor's successor in the IMU chain.
  void set_imu(const KeyFrameImu& imu);
  // A BA's estimate (has_imu() must hold); it makes the state `estimated`.
  void set_imu_velocity_and_bias(const Eigen::Vector3d& v, const inertial::ImuBias& bias);
  // The keyframe after this one in the IMU chain, null at its end.
  KeyFrame* imu_next() const;
  // Rotates the velocity with the world (Map::transform_world).
  void rotate_imu_velocity(const Eigen::Matrix3d& R_new_old);

  // Never removes the origin. Otherwise: detaches from points, lines and the graph,
  // re-parents its children to their best covisible candidate, and remembers its pose relative
  // to its parent so that frames that referenced it keep a valid pose. In the IMU chain its
  // successor follows its predecessor directly, with the two intervals' samples integrated again
  // as one (at the predecessor's bias).
  void set_bad();
  // Inline and lock-free, as Landmark::is_bad: local mapping asks it of every observing keyframe
  // of every landmark it touches.
  bool is_bad() const { return bad_.load(std::memory_order_acquire); }
  // For a bad keyframe: T_cp, its pose relative to its parent at the time it was culled.
  geometry::SE3 pose_relative_to_parent() const;

 private:
  const long id_;
  const bool origin_;
  const int segment_;
  const std::shared_ptr<const FrameData> data_;

  mutable std::mutex pose_mutex_;
  geometry::SE3 T_cw_;
  geometry::SE3 T_wc_;

  mutable std::mutex features_mutex_;
  std::vector<MapPoint*> points_;
  std::vector<MapLine*> lines_;

  mutable std::mutex imu_mutex_;
  std::optional<KeyFrameImu> imu_;
  KeyFrame* imu_next_ = nullptr;

  mutable std::mutex graph_mutex_;
  IdMap<KeyFrame, int> weights_;
  std::vector<KeyFrame*> ordered_;  // covisibles by decreasing weight
  KeyFrame* parent_ = nullptr;
  IdSet<KeyFrame> children_;
  IdSet<KeyFrame> loop_edges_;
  bool first_connection_ = true;
  // Set under graph_mutex_, after T_cp_ (release); read without it by is_bad().
  std::atomic<bool> bad_{false};
  geometry::SE3 T_cp_;

  void sort_connections_locked();
  // set_bad()'s part for the IMU chain.
  void leave_imu_chain();
};

}  // namespace plslam::map
