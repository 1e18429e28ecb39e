#include "plslam/map/map_line.h"

#include "plslam/map/landmark_impl.h"

namespace plslam::map {

template class Landmark<MapLine>;

MapLine::MapLine(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                 long created_frame)
    : Landmark(id, reference, created_frame), start_(start), end_(end) {}

Eigen::Vector3d MapLine::start() const {
  std::lock_guard lock(mutex_);
  return start_;
}

Eigen::Vector3d MapLine::end() const {
  std::lock_guard lock(mutex_);
  return end_;
}

Eigen::Vector3d MapLine::midpoint() const {
  std::lock_guard lock(mutex_);
  return 0.5 * (start_ + end_);
}

void MapLine::set_endpoints(const Eigen::Vector3d& start, const Eigen::Vector3d& end) {
  std::lock_guard lock(mutex_);
  start_ = start;
  end_ = end;
}

MapLine* MapLine::slot(const KeyFrame& kf, int index) { return kf.map_line(index); }

void MapLine::set_slot(KeyFrame& kf, int index, MapLine* value) {
  if (value) {
    kf.add_map_line(value, index);
  } else {
    kf.erase_map_line(index);
  }
}

cv::Mat MapLine::descriptor_row(const KeyFrame& kf, int index) { return kf.data().line_descriptors.row(index); }

bool MapLine::is_stereo(const KeyFrame& kf, int index) {
  return kf.data().lines.at(static_cast<std::size_t>(index)).stereo;
}

void MapLine::update_normal_and_depth() {
  const auto obs = observations();
  KeyFrame* ref = reference();
  const Eigen::Vector3d m = midpoint();
  if (obs.empty() || !ref) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, idx] : obs) normal += (m - kf->camera_center()).normalized();
  const double dist = (m - ref->camera_center()).norm();
  set_normal_and_range(normal.normalized(), 0.5 * dist, 2.0 * dist);
}

}  // namespace plslam::map
