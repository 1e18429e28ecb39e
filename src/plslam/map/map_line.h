#pragma once
// A 3D line landmark: a segment with two world endpoints, an LBD descriptor and its
// observations. Same ownership and locking rules as MapPoint.
#include <map>
#include <mutex>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace plslam::map {

class KeyFrame;

class MapLine {
 public:
  MapLine(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
          long created_frame);

  long id() const { return id_; }
  long created_frame() const { return created_frame_; }

  Eigen::Vector3d start() const;
  Eigen::Vector3d end() const;
  void set_endpoints(const Eigen::Vector3d& start, const Eigen::Vector3d& end);
  Eigen::Vector3d midpoint() const;

  void add_observation(KeyFrame* kf, int index);
  void erase_observation(KeyFrame* kf);
  std::map<KeyFrame*, int> observations() const;
  int num_observations() const;
  int index_in(const KeyFrame* kf) const;

  KeyFrame* reference() const;

  void update_descriptor();
  void update_normal_and_depth();
  cv::Mat descriptor() const;
  Eigen::Vector3d normal() const;
  double min_distance() const;
  double max_distance() const;

  void increase_visible(int n = 1);
  void increase_found(int n = 1);
  double found_ratio() const;

  bool is_bad() const;
  void set_bad();
  void replace_with(MapLine* other);
  MapLine* replaced_by() const;

 private:
  const long id_;
  const long created_frame_;
  mutable std::mutex mutex_;
  Eigen::Vector3d start_, end_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  cv::Mat descriptor_;
  std::map<KeyFrame*, int> observations_;
  KeyFrame* reference_;
  double min_distance_ = 0, max_distance_ = 0;
  int visible_ = 1, found_ = 1;
  bool bad_ = false;
  MapLine* replaced_by_ = nullptr;
};

}  // namespace plslam::map
