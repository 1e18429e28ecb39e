#pragma once
// Definitions of Landmark<Derived>; included by map_point.cpp and map_line.cpp only.
#include <algorithm>
#include <stdexcept>
#include <vector>

#include "plslam/map/descriptor_utils.h"
#include "plslam/map/keyframe.h"
#include "plslam/map/landmark.h"

namespace plslam::map {

namespace landmark_detail {
// The first observation whose keyframe id is not below kf's: kf's own if it is there.
template <class List>
auto lower_bound_by_id(List& list, const KeyFrame* kf) {
  return std::lower_bound(list.begin(), list.end(), kf->id(),
                          [](const auto& o, long id) { return o.first->id() < id; });
}
}  // namespace landmark_detail

template <class D>
bool Landmark<D>::add_observation(KeyFrame* kf, int index) {
  const int weight = D::is_stereo(*kf, index) ? 2 : 1;
  std::lock_guard lock(mutex_);
  if (bad_) return false;
  const auto it = landmark_detail::lower_bound_by_id(observations_, kf);
  if (it != observations_.end() && it->first->id() == kf->id()) {
    observation_weight_ -= D::is_stereo(*kf, it->second) ? 2 : 1;
    it->second = index;
  } else {
    observations_.emplace(it, kf, index);
  }
  observation_weight_ += weight;
  return true;
}

template <class D>
void Landmark<D>::erase_observation(KeyFrame* kf) {
  bool now_bad = false;
  {
    std::lock_guard lock(mutex_);
    const auto it = landmark_detail::lower_bound_by_id(observations_, kf);
    if (it == observations_.end() || it->first->id() != kf->id()) return;
    observation_weight_ -= D::is_stereo(*kf, it->second) ? 2 : 1;
    observations_.erase(it);
    if (reference_ == kf && !observations_.empty()) reference_ = observations_.begin()->first;
    // Seen by fewer than two keyframes, it carries no constraint between them: drop it.
    now_bad = observations_.size() <= 1 && !bad_;
  }
  if (now_bad) set_bad();
}

template <class D>
typename Landmark<D>::ObservationList Landmark<D>::observation_list() const {
  std::lock_guard lock(mutex_);
  return observations_;
}

template <class D>
int Landmark<D>::num_observations() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(observations_.size());
}

template <class D>
int Landmark<D>::observation_weight() const {
  std::lock_guard lock(mutex_);
  return observation_weight_;
}

template <class D>
int Landmark<D>::index_in(const KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  const auto it = landmark_detail::lower_bound_by_id(observations_, kf);
  return it == observations_.end() || it->first->id() != kf->id() ? -1 : it->second;
}

template <class D>
KeyFrame* Landmark<D>::reference() const {
  std::lock_guard lock(mutex_);
  return reference_;
}

template <class D>
void Landmark<D>::update_descriptor() {
  // Rows are read in place: the keyframes' descriptor matrices outlive this call (keyframes are
  // never freed), and only the chosen row is copied.
  auto observations = observation_list();
  std::erase_if(observations, [](const auto& o) { return o.first->is_bad(); });
  if (observations.empty()) return;
  std::vector<const uint8_t*> rows;
  rows.reserve(observations.size());
  for (const auto& [kf, idx] : observations) rows.push_back(D::descriptor_row(*kf, idx).template ptr<uint8_t>(0));
  const auto& [kf, idx] = observations[most_distinctive_index(rows)];
  cv::Mat best = D::descriptor_row(*kf, idx).clone();
  std::lock_guard lock(mutex_);
  descriptor_ = best;
}

template <class D>
cv::Mat Landmark<D>::descriptor() const {
  std::lock_guard lock(mutex_);
  // A deep copy: a cv::Mat copy would share the buffer (and its reference count) with the
  // mapping thread, which replaces the descriptor while tracking reads it.
  return descriptor_.clone();
}

template <class D>
bool Landmark<D>::copy_descriptor(std::array<uint8_t, 32>& out) const {
  std::lock_guard lock(mutex_);
  if (descriptor_.empty()) return false;
  if (!descriptor_.isContinuous() || descriptor_.total() * descriptor_.elemSize() != out.size()) {
    throw std::logic_error("a landmark descriptor is not 32 contiguous bytes");
  }
  std::copy_n(descriptor_.ptr<uint8_t>(0), out.size(), out.begin());
  return true;
}

template <class D>
Eigen::Vector3d Landmark<D>::normal() const {
  std::lock_guard lock(mutex_);
  return normal_;
}

template <class D>
double Landmark<D>::min_distance() const {
  std::lock_guard lock(mutex_);
  return min_distance_;
}

template <class D>
double Landmark<D>::max_distance() const {
  std::lock_guard lock(mutex_);
  return max_distance_;
}

template <class D>
void Landmark<D>::rotate_normal(const Eigen::Matrix3d& R) {
  std::lock_guard lock(mutex_);
  normal_ = R * normal_;
}

template <class D>
void Landmark<D>::set_normal_and_range(const Eigen::Vector3d& normal, double min_distance, double max_distance) {
  std::lock_guard lock(mutex_);
  normal_ = normal;
  min_distance_ = min_distance;
  max_distance_ = max_distance;
}

template <class D>
void Landmark<D>::increase_visible(int n) {
  std::lock_guard lock(mutex_);
  visible_ += n;
}

template <class D>
void Landmark<D>::increase_found(int n) {
  std::lock_guard lock(mutex_);
  found_ += n;
}

template <class D>
double Landmark<D>::found_ratio() const {
  std::lock_guard lock(mutex_);
  return static_cast<double>(found_) / std::max(visible_, 1);
}

template <class D>
void Landmark<D>::set_bad() {
  ObservationList obs;
  {
    std::lock_guard lock(mutex_);
    if (bad_.load(std::memory_order_relaxed)) return;
    bad_.store(true, std::memory_order_release);
    obs.swap(observations_);
    observation_weight_ = 0;
  }
  D* self = static_cast<D*>(this);
  for (const auto& [kf, idx] : obs) {
    if (D::slot(*kf, idx) == self) D::set_slot(*kf, idx, nullptr);
  }
}

template <class D>
void Landmark<D>::replace_with(D* other) {
  D* self = static_cast<D*>(this);
  if (other == self || !other) return;
  ObservationList obs;
  int visible = 0, found = 0;
  {
    std::lock_guard lock(mutex_);
    if (bad_.load(std::memory_order_relaxed)) return;
    bad_.store(true, std::memory_order_release);
    obs.swap(observations_);
    observation_weight_ = 0;
    visible = visible_;
    found = found_;
    replaced_by_ = other;
  }
  for (const auto& [kf, idx] : obs) {
    if (other->index_in(kf) < 0) {
      D::set_slot(*kf, idx, other);
      other->add_observation(kf, idx);
    } else if (D::slot(*kf, idx) == self) {
      D::set_slot(*kf, idx, nullptr);
    }
  }
  other->increase_visible(visible);
  other->increase_found(found);
  other->update_descriptor();
}

template <class D>
LandmarkState Landmark<D>::saved_state() const {
  std::lock_guard lock(mutex_);
  return {normal_, min_distance_, max_distance_, descriptor_.clone(), visible_, found_};
}

template <class D>
void Landmark<D>::restore_state(const LandmarkState& s) {
  std::lock_guard lock(mutex_);
  normal_ = s.normal;
  min_distance_ = s.min_distance;
  max_distance_ = s.max_distance;
  descriptor_ = s.descriptor.clone();
  visible_ = s.visible;
  found_ = s.found;
}

template <class D>
D* Landmark<D>::replaced_by() const {
  std::lock_guard lock(mutex_);
  return replaced_by_;
}

}  // namespace plslam::map
