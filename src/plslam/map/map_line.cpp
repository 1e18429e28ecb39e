#include "plslam/map/map_line.h"

#include <algorithm>

#include "plslam/map/descriptor_utils.h"
#include "plslam/map/keyframe.h"

namespace plslam::map {

MapLine::MapLine(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                 long created_frame)
    : id_(id), created_frame_(created_frame), start_(start), end_(end), reference_(reference) {}

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

void MapLine::add_observation(KeyFrame* kf, int index) {
  std::lock_guard lock(mutex_);
  observations_[kf] = index;
}

void MapLine::erase_observation(KeyFrame* kf) {
  bool now_bad = false;
  {
    std::lock_guard lock(mutex_);
    if (!observations_.erase(kf)) return;
    if (reference_ == kf && !observations_.empty()) reference_ = observations_.begin()->first;
    now_bad = observations_.size() <= 1 && !bad_;
  }
  if (now_bad) set_bad();
}

std::map<KeyFrame*, int> MapLine::observations() const {
  std::lock_guard lock(mutex_);
  return observations_;
}

int MapLine::num_observations() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(observations_.size());
}

int MapLine::index_in(const KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  const auto it = observations_.find(const_cast<KeyFrame*>(kf));
  return it == observations_.end() ? -1 : it->second;
}

KeyFrame* MapLine::reference() const {
  std::lock_guard lock(mutex_);
  return reference_;
}

void MapLine::update_descriptor() {
  std::vector<cv::Mat> descs;
  for (const auto& [kf, idx] : observations()) {
    if (!kf->is_bad()) descs.push_back(kf->data().line_descriptors.row(idx));
  }
  cv::Mat best = most_distinctive(descs);
  if (best.empty()) return;
  std::lock_guard lock(mutex_);
  descriptor_ = best;
}

void MapLine::update_normal_and_depth() {
  const auto obs = observations();
  KeyFrame* ref = reference();
  const Eigen::Vector3d m = midpoint();
  if (obs.empty() || !ref) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, idx] : obs) normal += (m - kf->camera_center()).normalized();
  const double dist = (m - ref->camera_center()).norm();
  std::lock_guard lock(mutex_);
  // Lines are detected on the finest level only; LBD bands tolerate about a factor of two either way.
  min_distance_ = 0.5 * dist;
  max_distance_ = 2.0 * dist;
  normal_ = normal.normalized();
}

cv::Mat MapLine::descriptor() const {
  std::lock_guard lock(mutex_);
  return descriptor_;
}

Eigen::Vector3d MapLine::normal() const {
  std::lock_guard lock(mutex_);
  return normal_;
}

double MapLine::min_distance() const {
  std::lock_guard lock(mutex_);
  return min_distance_;
}

double MapLine::max_distance() const {
  std::lock_guard lock(mutex_);
  return max_distance_;
}

void MapLine::increase_visible(int n) {
  std::lock_guard lock(mutex_);
  visible_ += n;
}

void MapLine::increase_found(int n) {
  std::lock_guard lock(mutex_);
  found_ += n;
}

double MapLine::found_ratio() const {
  std::lock_guard lock(mutex_);
  return static_cast<double>(found_) / std::max(visible_, 1);
}

bool MapLine::is_bad() const {
  std::lock_guard lock(mutex_);
  return bad_;
}

void MapLine::set_bad() {
  std::map<KeyFrame*, int> obs;
  {
    std::lock_guard lock(mutex_);
    if (bad_) return;
    bad_ = true;
    obs.swap(observations_);
  }
  for (const auto& [kf, idx] : obs) {
    if (kf->map_line(idx) == this) kf->erase_map_line(idx);
  }
}

void MapLine::replace_with(MapLine* other) {
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
      kf->add_map_line(other, idx);
      other->add_observation(kf, idx);
    } else if (kf->map_line(idx) == this) {
      kf->erase_map_line(idx);
    }
  }
  other->increase_visible(visible);
  other->increase_found(found);
  other->update_descriptor();
}

MapLine* MapLine::replaced_by() const {
  std::lock_guard lock(mutex_);
  return replaced_by_;
}

}  // namespace plslam::map
