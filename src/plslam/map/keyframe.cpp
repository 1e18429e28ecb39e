#include "plslam/map/keyframe.h"

#include <algorithm>
#include <stdexcept>

#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::map {

KeyFrame::KeyFrame(long id, std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw, bool origin,
                   int segment)
    : id_(id), origin_(origin), segment_(segment), data_(std::move(data)), T_cw_(T_cw), T_wc_(T_cw.inverse()),
      points_(data_->keypoints.size(), nullptr), lines_(data_->lines.size(), nullptr) {}

geometry::SE3 KeyFrame::pose() const {
  std::lock_guard lock(pose_mutex_);
  return T_cw_;
}

geometry::SE3 KeyFrame::pose_inverse() const {
  std::lock_guard lock(pose_mutex_);
  return T_wc_;
}

Eigen::Vector3d KeyFrame::camera_center() const {
  std::lock_guard lock(pose_mutex_);
  return T_wc_.translation();
}

void KeyFrame::set_pose(const geometry::SE3& T_cw) {
  std::lock_guard lock(pose_mutex_);
  T_cw_ = T_cw.normalized();
  T_wc_ = T_cw_.inverse();
}

void KeyFrame::add_map_point(MapPoint* p, int index) {
  std::lock_guard lock(features_mutex_);
  points_.at(static_cast<std::size_t>(index)) = p;
}

void KeyFrame::erase_map_point(int index) {
  std::lock_guard lock(features_mutex_);
  points_.at(static_cast<std::size_t>(index)) = nullptr;
}

void KeyFrame::erase_map_point(const MapPoint* p) {
  std::lock_guard lock(features_mutex_);
  for (auto& q : points_) {
    if (q == p) q = nullptr;
  }
}

MapPoint* KeyFrame::map_point(int index) const {
  std::lock_guard lock(features_mutex_);
  return points_.at(static_cast<std::size_t>(index));
}

std::vector<MapPoint*> KeyFrame::map_points() const {
  std::lock_guard lock(features_mutex_);
  return points_;
}

int KeyFrame::tracked_map_points(int min_obs) const {
  const auto pts = map_points();
  int n = 0;
  for (const auto* p : pts) {
    if (p && !p->is_bad() && p->observation_weight() >= min_obs) ++n;
  }
  return n;
}

void KeyFrame::add_map_line(MapLine* l, int index) {
  std::lock_guard lock(features_mutex_);
  lines_.at(static_cast<std::size_t>(index)) = l;
}

void KeyFrame::erase_map_line(int index) {
  std::lock_guard lock(features_mutex_);
  lines_.at(static_cast<std::size_t>(index)) = nullptr;
}

void KeyFrame::erase_map_line(const MapLine* l) {
  std::lock_guard lock(features_mutex_);
  for (auto& q : lines_) {
    if (q == l) q = nullptr;
  }
}

MapLine* KeyFrame::map_line(int index) const {
  std::lock_guard lock(features_mutex_);
  return lines_.at(static_cast<std::size_t>(index));
}

std::vector<MapLine*> KeyFrame::map_lines() const {
  std::lock_guard lock(features_mutex_);
  return lines_;
}

int KeyFrame::tracked_map_lines(int min_obs) const {
  const auto ls = map_lines();
  int n = 0;
  for (const auto* l : ls) {
    if (l && !l->is_bad() && l->observation_weight() >= min_obs) ++n;
  }
  return n;
}

void KeyFrame::sort_connections_locked() {
  std::vector<std::pair<int, KeyFrame*>> v;
  v.reserve(weights_.size());
  for (const auto& [kf, w] : weights_) v.emplace_back(w, kf);
  // Ties broken by id so that the order does not depend on pointer values.
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id() < b.second->id();
  });
  ordered_.clear();
  for (const auto& [w, kf] : v) ordered_.push_back(kf);
}

void KeyFrame::add_connection(KeyFrame* kf, int weight) {
  std::lock_guard lock(graph_mutex_);
  weights_[kf] = weight;
  sort_connections_locked();
}

void KeyFrame::erase_connection(KeyFrame* kf) {
  std::lock_guard lock(graph_mutex_);
  if (weights_.erase(kf)) sort_connections_locked();
}

void KeyFrame::update_connections(int min_shared) {
  IdMap<KeyFrame, int> counter;
  for (const auto* p : map_points()) {
    if (!p || p->is_bad()) continue;
    p->for_each_observation([&](KeyFrame* kf, int) {
      if (kf != this) ++counter[kf];
    });
  }
  for (const auto* l : map_lines()) {
    if (!l || l->is_bad()) continue;
    l->for_each_observation([&](KeyFrame* kf, int) {
      if (kf != this) ++counter[kf];
    });
  }
  if (counter.empty()) return;
  KeyFrame* best = nullptr;
  int best_w = 0;
  IdMap<KeyFrame, int> kept;
  for (const auto& [kf, w] : counter) {
    if (kf->is_bad()) continue;
    if (w > best_w || (w == best_w && best && kf->id() < best->id())) {
      best_w = w;
      best = kf;
    }
    if (w >= min_shared) kept[kf] = w;
  }
  if (!best) return;
  if (kept.empty()) kept[best] = best_w;
  for (const auto& [kf, w] : kept) kf->add_connection(this, w);

  std::lock_guard lock(graph_mutex_);
  weights_ = std::move(kept);
  sort_connections_locked();
  if (first_connection_ && id_ != 0) {
    parent_ = ordered_.front();
    parent_->add_child(this);
    first_connection_ = false;
  }
}

std::vector<KeyFrame*> KeyFrame::covisibles() const {
  std::lock_guard lock(graph_mutex_);
  return ordered_;
}

std::vector<KeyFrame*> KeyFrame::best_covisibles(std::size_t n) const {
  std::lock_guard lock(graph_mutex_);
  return {ordered_.begin(), ordered_.begin() + static_cast<std::ptrdiff_t>(std::min(n, ordered_.size()))};
}

int KeyFrame::weight(const KeyFrame* kf) const {
  std::lock_guard lock(graph_mutex_);
  const auto it = weights_.find(const_cast<KeyFrame*>(kf));
  return it == weights_.end() ? 0 : it->second;
}

KeyFrame* KeyFrame::parent() const {
  std::lock_guard lock(graph_mutex_);
  return parent_;
}

IdSet<KeyFrame> KeyFrame::children() const {
  std::lock_guard lock(graph_mutex_);
  return children_;
}

void KeyFrame::add_child(KeyFrame* kf) {
  std::lock_guard lock(graph_mutex_);
  children_.insert(kf);
}

void KeyFrame::erase_child(KeyFrame* kf) {
  std::lock_guard lock(graph_mutex_);
  children_.erase(kf);
}

void KeyFrame::change_parent(KeyFrame* kf) {
  {
    std::lock_guard lock(graph_mutex_);
    parent_ = kf;
  }
  kf->add_child(this);
}

geometry::SE3 KeyFrame::pose_relative_to_parent() const {
  std::lock_guard lock(graph_mutex_);
  return T_cp_;
}

void KeyFrame::add_loop_edge(KeyFrame* kf) {
  std::lock_guard lock(graph_mutex_);
  loop_edges_.insert(kf);
}

void KeyFrame::restore_graph(KeyFrame* parent, const IdMap<KeyFrame, int>& weights,
                             const IdSet<KeyFrame>& loop_edges) {
  {
    std::lock_guard lock(graph_mutex_);
    weights_ = weights;
    sort_connections_locked();
    loop_edges_ = loop_edges;
    first_connection_ = false;
    parent_ = parent;
  }
  if (parent) parent->add_child(this);
}

IdSet<KeyFrame> KeyFrame::loop_edges() const {
  std::lock_guard lock(graph_mutex_);
  return loop_edges_;
}

void KeyFrame::move_to(const geometry::SE3& T_cw) {
  const Eigen::Matrix3d R_before = pose().rotation();
  set_pose(T_cw);
  rotate_imu_velocity(pose().rotation().transpose() * R_before);  // R_wc_new R_wc_old'
}

bool KeyFrame::has_imu() const {
  std::lock_guard lock(imu_mutex_);
  return imu_.has_value();
}

std::optional<KeyFrameImu> KeyFrame::imu() const {
  std::lock_guard lock(imu_mutex_);
  return imu_;
}

void KeyFrame::set_imu(const KeyFrameImu& imu) {
  {
    std::lock_guard lock(imu_mutex_);
    imu_ = imu;
  }
  if (imu.previous) {
    std::lock_guard lock(imu.previous->imu_mutex_);
    imu.previous->imu_next_ = this;
  }
}

void KeyFrame::set_imu_velocity_and_bias(const Eigen::Vector3d& v, const inertial::ImuBias& bias) {
  std::lock_guard lock(imu_mutex_);
  if (!imu_) throw std::logic_error("KeyFrame::set_imu_velocity_and_bias: no IMU state");
  imu_->v = v;
  imu_->bias = bias;
  imu_->estimated = true;
}

KeyFrame* KeyFrame::imu_next() const {
  std::lock_guard lock(imu_mutex_);
  return imu_next_;
}

void KeyFrame::rotate_imu_velocity(const Eigen::Matrix3d& R_new_old) {
  std::lock_guard lock(imu_mutex_);
  if (imu_) imu_->v = R_new_old * imu_->v;
}

void KeyFrame::leave_imu_chain() {
  // One keyframe's IMU lock at a time, so that no two threads can wait on each other.
  std::optional<KeyFrameImu> own;
  KeyFrame* next = nullptr;
  {
    std::lock_guard lock(imu_mutex_);
    if (!imu_) return;
    own = imu_;
    next = imu_next_;
    imu_next_ = nullptr;
    imu_->previous = nullptr;
    imu_->from_previous.reset();
  }
  KeyFrame* previous = own->previous;
  std::optional<inertial::ImuBias> previous_bias;
  if (previous) {
    std::lock_guard lock(previous->imu_mutex_);
    previous->imu_next_ = next;
    if (previous->imu_) previous_bias = previous->imu_->bias;
  }
  if (!next) return;
  std::lock_guard lock(next->imu_mutex_);
  if (!next->imu_) return;
  auto& after = next->imu_->from_previous;
  if (!previous_bias || !own->from_previous || !after) {
    next->imu_->previous = nullptr;
    after.reset();
    return;
  }
  // The two intervals as one: the second's first sample is the first's last (both interpolated at
  // this keyframe's time).
  std::vector<ImuSample> samples = own->from_previous->samples();
  samples.insert(samples.end(), after->samples().begin() + 1, after->samples().end());
  after = std::make_shared<const inertial::Preintegration>(samples, own->from_previous->t_i(), after->t_j(),
                                                           *previous_bias, after->noise());
  next->imu_->previous = previous;
}

void KeyFrame::set_bad() {
  if (origin_) return;
  leave_imu_chain();
  for (auto* kf : covisibles()) kf->erase_connection(this);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (auto* p = map_point(static_cast<int>(i))) p->erase_observation(this);
  }
  for (std::size_t i = 0; i < lines_.size(); ++i) {
    if (auto* l = map_line(static_cast<int>(i))) l->erase_observation(this);
  }
  KeyFrame* parent = nullptr;
  IdSet<KeyFrame> children;
  {
    std::lock_guard lock(graph_mutex_);
    weights_.clear();
    ordered_.clear();
    parent = parent_;
    children = children_;
    children_.clear();
  }
  {
    std::lock_guard lock(features_mutex_);
    std::fill(points_.begin(), points_.end(), nullptr);
    std::fill(lines_.begin(), lines_.end(), nullptr);
  }
  // Spanning-tree repair (as ORB-SLAM2): each child moves to the candidate parent it shares most
  // with; candidates start as this keyframe's parent and grow with every re-parented child.
  IdSet<KeyFrame> candidates;
  if (parent) candidates.insert(parent);
  while (!children.empty()) {
    KeyFrame* best_child = nullptr;
    KeyFrame* best_parent = nullptr;
    int best_w = -1;
    for (auto* child : children) {
      if (child->is_bad()) continue;
      for (auto* c : candidates) {
        const int w = child->weight(c);
        if (w > best_w) {
          best_w = w;
          best_child = child;
          best_parent = c;
        }
      }
    }
    if (!best_child || best_w <= 0) break;
    best_child->change_parent(best_parent);
    candidates.insert(best_child);
    children.erase(best_child);
  }
  for (auto* child : children) {
    if (parent) child->change_parent(parent);
  }
  if (parent) parent->erase_child(this);
  std::lock_guard lock(graph_mutex_);
  if (parent) T_cp_ = pose() * parent->pose_inverse();
  bad_.store(true, std::memory_order_release);
}

}  // namespace plslam::map
