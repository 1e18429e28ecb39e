#include "plslam/map/map_point.h"

#include <algorithm>
#include <cmath>

#include "plslam/map/landmark_impl.h"

namespace plslam::map {

template class Landmark<MapPoint>;

MapPoint::MapPoint(long id, const Eigen::Vector3d& position, KeyFrame* reference, long created_frame)
    : Landmark(id, reference, created_frame), position_(position) {}

Eigen::Vector3d MapPoint::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

void MapPoint::set_position(const Eigen::Vector3d& p) {
  std::lock_guard lock(mutex_);
  position_ = p;
}

MapPoint* MapPoint::slot(const KeyFrame& kf, int index) { return kf.map_point(index); }

void MapPoint::set_slot(KeyFrame& kf, int index, MapPoint* value) {
  if (value) {
    kf.add_map_point(value, index);
  } else {
    kf.erase_map_point(index);
  }
}

cv::Mat MapPoint::descriptor_row(const KeyFrame& kf, int index) { return kf.data().descriptors.row(index); }

bool MapPoint::is_stereo(const KeyFrame& kf, int index) {
  return kf.data().u_right.at(static_cast<std::size_t>(index)) >= 0;
}

void MapPoint::update_normal_and_depth() {
  const auto obs = observation_list();
  KeyFrame* ref = reference();
  const Eigen::Vector3d p = position();
  if (obs.empty() || !ref) return;
  const auto ref_it = std::find_if(obs.begin(), obs.end(), [ref](const auto& o) { return o.first == ref; });
  if (ref_it == obs.end()) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, idx] : obs) normal += (p - kf->camera_center()).normalized();
  const auto& data = ref->data();
  const double dist = (p - ref->camera_center()).norm();
  const int level = data.keypoints[static_cast<std::size_t>(ref_it->second)].octave;
  const double max_d = dist * data.level_scale(level);
  const double min_d = max_d / data.level_scale(data.levels - 1);
  set_normal_and_range(normal.normalized(), 0.8 * min_d, 1.2 * max_d);
  std::lock_guard lock(mutex_);
  level0_max_distance_ = max_d;
}

double MapPoint::level0_max_distance() const {
  std::lock_guard lock(mutex_);
  return level0_max_distance_;
}

void MapPoint::restore_level0_max_distance(double d) {
  std::lock_guard lock(mutex_);
  level0_max_distance_ = d;
}

int MapPoint::predict_level(double distance, int levels, double scale_factor) const {
  double ratio = 0;
  {
    std::lock_guard lock(mutex_);
    ratio = level0_max_distance_ / std::max(distance, 1e-9);
  }
  const int level = static_cast<int>(std::ceil(std::log(std::max(ratio, 1e-9)) / std::log(scale_factor)));
  return std::clamp(level, 0, levels - 1);
}

}  // namespace plslam::map
