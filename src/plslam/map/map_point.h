#pragma once
// A 3D point landmark. Owned by the Map; everything else holds non-owning pointers that stay valid
// for the Map's lifetime (culled points are flagged bad, never freed early). Position, descriptor
// and observations are guarded by the point's own mutex, since tracking reads them while the
// local mapping thread writes them.
#include <map>
#include <mutex>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace plslam::map {

class KeyFrame;

class MapPoint {
 public:
  MapPoint(long id, const Eigen::Vector3d& position, KeyFrame* reference, long created_frame);

  long id() const { return id_; }
  long created_frame() const { return created_frame_; }

  Eigen::Vector3d position() const;
  void set_position(const Eigen::Vector3d& p);

  // Observations: keyframe -> index of the keypoint in that keyframe.
  void add_observation(KeyFrame* kf, int index);
  void erase_observation(KeyFrame* kf);
  std::map<KeyFrame*, int> observations() const;
  int num_observations() const;
  int index_in(const KeyFrame* kf) const;  // -1 if not observed there

  KeyFrame* reference() const;

  // The most distinctive descriptor among the observations (smallest median Hamming distance to
  // the others), the mean viewing direction, and the scale-invariance distance range.
  void update_descriptor();
  void update_normal_and_depth();
  cv::Mat descriptor() const;
  Eigen::Vector3d normal() const;
  double min_distance() const;
  double max_distance() const;
  // Pyramid level at which a point seen at `distance` should be detected.
  int predict_level(double distance, int levels, double scale_factor) const;

  // Tracking statistics for culling: how often it was predicted visible vs actually matched.
  void increase_visible(int n = 1);
  void increase_found(int n = 1);
  double found_ratio() const;

  bool is_bad() const;
  // Flags the point bad and removes it from every observing keyframe.
  void set_bad();
  // Replaces this point by `other` in every keyframe that observes it (fusion of duplicates).
  void replace_with(MapPoint* other);
  MapPoint* replaced_by() const;

 private:
  const long id_;
  const long created_frame_;
  mutable std::mutex mutex_;
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  cv::Mat descriptor_;
  std::map<KeyFrame*, int> observations_;
  KeyFrame* reference_;
  double min_distance_ = 0, max_distance_ = 0;
  int visible_ = 1, found_ = 1;
  bool bad_ = false;
  MapPoint* replaced_by_ = nullptr;
};

}  // namespace plslam::map
