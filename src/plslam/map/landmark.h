#pragma once
// What map points and map lines have in common: observations by keyframes, a representative
// descriptor, a mean viewing direction and distance range, tracking statistics for culling, and
// the bad/replaced flags. Derived (CRTP) says where it sits in a keyframe:
//   static Derived* slot(const KeyFrame&, int index);
//   static void set_slot(KeyFrame&, int index, Derived* value);
//   static cv::Mat descriptor_row(const KeyFrame&, int index);
//   static bool is_stereo(const KeyFrame&, int index);  // also matched in the right image
// Owned by the Map; the state is guarded by the landmark's own mutex because tracking reads it
// while local mapping writes it. Member definitions: landmark_impl.h, instantiated by the derived
// classes' .cpp files.
#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace plslam::map {

class KeyFrame;

// A landmark's representative descriptor, viewing direction and distance range, and tracking
// statistics (see Landmark).
struct LandmarkState {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double min_distance = 0, max_distance = 0;
  cv::Mat descriptor;  // 1 x 32 CV_8U, or empty
  int visible = 1, found = 1;
};

template <class Derived>
class Landmark {
 public:
  Landmark(long id, KeyFrame* reference, long created_frame)
      : id_(id), created_frame_(created_frame), reference_(reference) {}

  long id() const { return id_; }
  long created_frame() const { return created_frame_; }

  // Observations: keyframe -> index of the feature in that keyframe, in keyframe-id order (never
  // address order, see by_id.h). A flat sorted vector rather than a std::map: a landmark has a
  // handful of observations, and the local BA window, the landmark updates and keyframe culling
  // copy or walk those of thousands of landmarks per keyframe (the tree walk alone was 5 % of a
  // street run's CPU).
  using ObservationList = std::vector<std::pair<KeyFrame*, int>>;
  // A bad landmark takes none (returns false): the caller must not leave it in the keyframe's
  // slot, where it would outlive reclamation (Map::reclaim).
  bool add_observation(KeyFrame* kf, int index);
  // Removes one; a landmark left with fewer than two observing keyframes turns bad.
  void erase_observation(KeyFrame* kf);
  ObservationList observation_list() const;
  // Calls f(keyframe, index) for each observation under the landmark's lock, without the copy
  // observation_list() makes (the per-frame covisibility counts visit thousands of landmarks).
  // f must take no lock and must not call back into this landmark.
  template <typename F>
  void for_each_observation(F&& f) const {
    std::lock_guard lock(mutex_);
    for (const auto& [kf, index] : observations_) f(kf, index);
  }
  int num_observations() const;  // observing keyframes
  // ORB-SLAM's observation count: a stereo observation counts 2, a left-only one 1, because a
  // stereo observation alone fixes the landmark's position. The keyframe decision (tracked map
  // points of the reference) and the culling rules use this count, as ORB-SLAM2/3 do.
  int observation_weight() const;
  int index_in(const KeyFrame* kf) const;  // -1 if not observed there
  KeyFrame* reference() const;

  // The most distinctive descriptor among the observations (smallest median Hamming distance).
  void update_descriptor();
  cv::Mat descriptor() const;  // the caller's own copy
  // The same 32 bytes without a heap copy, for the matching loops that read one per landmark;
  // false (and `out` untouched) while the landmark has no descriptor.
  bool copy_descriptor(std::array<uint8_t, 32>& out) const;
  Eigen::Vector3d normal() const;
  // The world turned by R (Map::transform_world): the mean viewing direction turns with it.
  void rotate_normal(const Eigen::Matrix3d& R);
  double min_distance() const;
  double max_distance() const;

  // Tracking statistics: how often it was predicted visible vs actually matched.
  void increase_visible(int n = 1);
  void increase_found(int n = 1);
  double found_ratio() const;

  // Inline: tracking calls it for every landmark it touches (3 % of a street run's profile as an
  // out-of-line call).
  bool is_bad() const { return bad_.load(std::memory_order_acquire); }
  // Flags it bad and removes it from every observing keyframe.
  void set_bad();
  // Hands its observations over to `other` (fusion of duplicates) and turns bad.
  void replace_with(Derived* other);
  Derived* replaced_by() const;

  // What a map file stores beyond the position and the observations (system/map_file): restored
  // as saved rather than recomputed, so that save -> load -> save gives the same bytes.
  LandmarkState saved_state() const;
  void restore_state(const LandmarkState& s);

 protected:
  // For update_normal_and_depth() of the derived class: the mean viewing direction and range.
  void set_normal_and_range(const Eigen::Vector3d& normal, double min_distance, double max_distance);

  mutable std::mutex mutex_;

 private:
  const long id_;
  const long created_frame_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  cv::Mat descriptor_;
  ObservationList observations_;  // sorted by keyframe id
  int observation_weight_ = 0;
  KeyFrame* reference_;
  double min_distance_ = 0, max_distance_ = 0;
  int visible_ = 1, found_ = 1;
  // Written under mutex_; read without it by is_bad(), which tracking and reclamation call for
  // every landmark they touch.
  std::atomic<bool> bad_{false};
  Derived* replaced_by_ = nullptr;
};

}  // namespace plslam::map
