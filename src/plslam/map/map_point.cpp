#include "plslam/map/map_point.h"

#include <algorithm>
#include <cmath>

#include "plslam/map/descriptor_utils.h"
#include "plslam/map/keyframe.h"

namespace plslam::map {

MapPoint::MapPoint(long id, const Eigen::Vector3d& position, KeyFrame* reference, long created_frame)
    : id_(id), created_frame_(created_frame), position_(position), reference_(reference) {}

Eigen::Vector3d MapPoint::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

void MapPoint::set_position(const Eigen::Vector3d& p) {
  std::lock_guard lock(mutex_);
  position_ = p;
}

void MapPoint::add_observation(KeyFrame* kf, int index) {
  std::lock_guard lock(mutex_);
  observations_[kf] = index;
}

void MapPoint::erase_observation(KeyFrame* kf) {
  bool now_bad = false;
  {
    std::lock_guard lock(mutex_);
    if (!observations_.erase(kf)) return;
    if (reference_ == kf && !observations_.empty()) reference_ = observations_.begin()->first;
    // A point seen by fewer than two keyframes carries no constraint: drop it.
    now_bad = observations_.size() <= 1 && !bad_;
  }
  if (now_bad) set_bad();
}

std::map<KeyFrame*, int> MapPoint::observations() const {
  std::lock_guard lock(mutex_);
  return observations_;
}

int MapPoint::num_observations() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(observations_.size());
}

int MapPoint::index_in(const KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  const auto it = observations_.find(const_cast<KeyFrame*>(kf));
  return it == observations_.end() ? -1 : it->second;
}

KeyFrame* MapPoint::reference() const {
  std::lock_guard lock(mutex_);
  return reference_;
}

void MapPoint::update_descriptor() {
  std::vector<cv::Mat> descs;
  for (const auto& [kf, idx] : observations()) {
    if (!kf->is_bad()) descs.push_back(kf->data().descriptors.row(idx));
  }
  cv::Mat best = most_distinctive(descs);
  if (best.empty()) return;
  std::lock_guard lock(mutex_);
  descriptor_ = best;
}

void MapPoint::update_normal_and_depth() {
  const auto obs = observations();
  KeyFrame* ref = reference();
  const Eigen::Vector3d p = position();
  if (obs.empty() || !ref) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, idx] : obs) normal += (p - kf->camera_center()).normalized();
  const auto ref_it = obs.find(ref);
  if (ref_it == obs.end()) return;
  const auto& data = ref->data();
  const double dist = (p - ref->camera_center()).norm();
  const int level = data.keypoints[static_cast<std::size_t>(ref_it->second)].octave;
  std::lock_guard lock(mutex_);
  max_distance_ = dist * data.level_scale(level);
  min_distance_ = max_distance_ / data.level_scale(data.levels - 1);
  normal_ = normal.normalized();
}

cv::Mat MapPoint::descriptor() const {
  std::lock_guard lock(mutex_);
  return descriptor_;
}

Eigen::Vector3d MapPoint::normal() const {
  std::lock_guard lock(mutex_);
  return normal_;
}

double MapPoint::min_distance() const {
  std::lock_guard lock(mutex_);
  return 0.8 * min_distance_;
}

double MapPoint::max_distance() const {
  std::lock_guard lock(mutex_);
  return 1.2 * max_distance_;
}

int MapPoint::predict_level(double distance, int levels, double scale_factor) const {
  double ratio = 0;
  {
    std::lock_guard lock(mutex_);
    ratio = max_distance_ / std::max(distance, 1e-9);
  }
  const int level = static_cast<int>(std::ceil(std::log(std::max(ratio, 1e-9)) / std::log(scale_factor)));
  return std::clamp(level, 0, levels - 1);
}

void MapPoint::increase_visible(int n) {
  std::lock_guard lock(mutex_);
  visible_ += n;
}

void MapPoint::increase_found(int n) {
  std::lock_guard lock(mutex_);
  found_ += n;
}

double MapPoint::found_ratio() const {
  std::lock_guard lock(mutex_);
  return static_cast<double>(found_) / std::max(visible_, 1);
}

bool MapPoint::is_bad() const {
  std::lock_guard lock(mutex_);
  return bad_;
}

void MapPoint::set_bad() {
  std::map<KeyFrame*, int> obs;
  {
    std::lock_guard lock(mutex_);
    if (bad_) return;
    bad_ = true;
    obs.swap(observations_);
  }
  for (const auto& [kf, idx] : obs) {
    if (kf->map_point(idx) == this) kf->erase_map_point(idx);
  }
}

void MapPoint::replace_with(MapPoint* other) {
  if (other == this || !other) return;
  std::map<KeyFrame*, int> obs;
  int visible = 0, found = 0;
  {
    std::lock_guard lock(mutex_);
    if (bad_) return;
    bad_ = true;
    obs.swap(observations_);
    visible = visible_;
    found = found_;
    replaced_by_ = other;
  }
  for (const auto& [kf, idx] : obs) {
    if (other->index_in(kf) < 0) {
      kf->add_map_point(other, idx);
      other->add_observation(kf, idx);
    } else if (kf->map_point(idx) == this) {
      kf->erase_map_point(idx);
    }
  }
  other->increase_visible(visible);
  other->increase_found(found);
  other->update_descriptor();
}

MapPoint* MapPoint::replaced_by() const {
  std::lock_guard lock(mutex_);
  return replaced_by_;
}

}  // namespace plslam::map
