#include "plslam/map/map.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace plslam::map {

KeyFrame* Map::create_keyframe(std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw, int segment) {
  std::lock_guard lock(mutex_);
  ++changes_;
  if (segment < 0 || segment >= static_cast<int>(segment_parent_.size())) {
    throw std::invalid_argument("unknown map segment " + std::to_string(segment));
  }
  const bool origin = all_keyframes_.empty();
  all_keyframes_.push_back(
      std::make_unique<KeyFrame>(next_keyframe_id_++, std::move(data), T_cw, origin, segment));
  keyframes_.insert(all_keyframes_.back().get());
  return all_keyframes_.back().get();
}

MapPoint* Map::create_point(const Eigen::Vector3d& position, KeyFrame* reference, long frame_id) {
  std::lock_guard lock(mutex_);
  ++changes_;
  all_points_.push_back(std::make_unique<MapPoint>(next_point_id_++, position, reference, frame_id));
  points_.insert(all_points_.back().get());
  return all_points_.back().get();
}

MapLine* Map::create_line(const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                          long frame_id) {
  std::lock_guard lock(mutex_);
  ++changes_;
  all_lines_.push_back(std::make_unique<MapLine>(next_line_id_++, start, end, reference, frame_id));
  lines_.insert(all_lines_.back().get());
  return all_lines_.back().get();
}

KeyFrame* Map::restore_keyframe(long id, std::shared_ptr<const FrameData> data, const geometry::SE3& T_cw) {
  std::lock_guard lock(mutex_);
  ++changes_;
  if (id < 0) throw std::invalid_argument("negative keyframe id");
  // Map files list keyframes by increasing id: the first restored is the saved map's origin.
  const bool origin = all_keyframes_.empty();
  all_keyframes_.push_back(std::make_unique<KeyFrame>(id, std::move(data), T_cw, origin));
  if (!keyframes_.insert(all_keyframes_.back().get()).second) {
    all_keyframes_.pop_back();
    throw std::invalid_argument("duplicate keyframe id " + std::to_string(id));
  }
  next_keyframe_id_ = std::max(next_keyframe_id_, id + 1);
  return all_keyframes_.back().get();
}

MapPoint* Map::restore_point(long id, const Eigen::Vector3d& position, KeyFrame* reference, long frame_id) {
  std::lock_guard lock(mutex_);
  ++changes_;
  if (id < 0) throw std::invalid_argument("negative point id");
  all_points_.push_back(std::make_unique<MapPoint>(id, position, reference, frame_id));
  if (!points_.insert(all_points_.back().get()).second) {
    all_points_.pop_back();
    throw std::invalid_argument("duplicate point id " + std::to_string(id));
  }
  next_point_id_ = std::max(next_point_id_, id + 1);
  return all_points_.back().get();
}

MapLine* Map::restore_line(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                           long frame_id) {
  std::lock_guard lock(mutex_);
  ++changes_;
  if (id < 0) throw std::invalid_argument("negative line id");
  all_lines_.push_back(std::make_unique<MapLine>(id, start, end, reference, frame_id));
  if (!lines_.insert(all_lines_.back().get()).second) {
    all_lines_.pop_back();
    throw std::invalid_argument("duplicate line id " + std::to_string(id));
  }
  next_line_id_ = std::max(next_line_id_, id + 1);
  return all_lines_.back().get();
}

Map::NextIds Map::next_ids() const {
  std::lock_guard lock(mutex_);
  return {next_keyframe_id_, next_point_id_, next_line_id_};
}

void Map::restore_next_ids(const NextIds& next) {
  std::lock_guard lock(mutex_);
  next_keyframe_id_ = std::max(next_keyframe_id_, next.keyframe);
  next_point_id_ = std::max(next_point_id_, next.point);
  next_line_id_ = std::max(next_line_id_, next.line);
}

void Map::erase_keyframe(KeyFrame* kf) {
  std::lock_guard lock(mutex_);
  ++changes_;
  keyframes_.erase(kf);
}

void Map::erase_point(MapPoint* p) {
  p->set_bad();
  std::lock_guard lock(mutex_);
  ++changes_;
  points_.erase(p);
}

void Map::erase_line(MapLine* l) {
  l->set_bad();
  std::lock_guard lock(mutex_);
  ++changes_;
  lines_.erase(l);
}

namespace {

// Frees the bad objects of `all` (and drops them from the active set); returns how many.
template <class Object>
int free_bad(std::vector<std::unique_ptr<Object>>& all, IdSet<Object>& active_set) {
  return static_cast<int>(std::erase_if(all, [&](const std::unique_ptr<Object>& o) {
    if (!o->is_bad()) return false;
    active_set.erase(o.get());
    return true;
  }));
}

}  // namespace

Map::Reclaimed Map::reclaim(const std::function<void()>& drop_bad) {
  std::unique_lock hold(objects_mutex_);
  if (drop_bad) drop_bad();
  std::lock_guard lock(mutex_);
  Reclaimed r;
  r.points = free_bad(all_points_, points_);
  r.lines = free_bad(all_lines_, lines_);
  reclaimed_.points += r.points;
  reclaimed_.lines += r.lines;
  return r;
}

void Map::transform_world(const geometry::SE3& T_new_old) {
  std::lock_guard update(update_mutex_);
  const geometry::SE3 T_old_new = T_new_old.inverse();
  const Eigen::Matrix3d& R = T_new_old.rotation();
  // The objects' own locks are taken after mutex_ is released, as everywhere else.
  std::vector<KeyFrame*> keyframes;
  std::vector<MapPoint*> points;
  std::vector<MapLine*> lines;
  {
    std::lock_guard lock(mutex_);
    for (const auto& kf : all_keyframes_) keyframes.push_back(kf.get());
    for (const auto& p : all_points_) points.push_back(p.get());
    for (const auto& l : all_lines_) lines.push_back(l.get());
  }
  for (KeyFrame* kf : keyframes) {
    kf->set_pose(kf->pose() * T_old_new);
    kf->rotate_imu_velocity(R);
  }
  for (MapPoint* p : points) {
    p->set_position(T_new_old * p->position());
    p->rotate_normal(R);
  }
  for (MapLine* l : lines) {
    l->set_endpoints(T_new_old * l->start(), T_new_old * l->end());
    l->rotate_normal(R);
  }
  ++changes_;
}

Map::Reclaimed Map::reclaimed() const {
  std::lock_guard lock(mutex_);
  return reclaimed_;
}

namespace {

// Objects can turn bad from other threads (e.g. a point losing its last observations); the
// active sets drop them lazily here.
template <class Set>
std::vector<typename Set::key_type> active(Set& set) {
  std::vector<typename Set::key_type> out;
  out.reserve(set.size());
  for (auto it = set.begin(); it != set.end();) {
    if ((*it)->is_bad()) {
      it = set.erase(it);
    } else {
      out.push_back(*it++);
    }
  }
  return out;
}

}  // namespace

std::vector<KeyFrame*> Map::keyframes() const {
  std::lock_guard lock(mutex_);
  return active(keyframes_);
}

std::vector<MapPoint*> Map::points() const {
  std::lock_guard lock(mutex_);
  return active(points_);
}

std::vector<MapLine*> Map::lines() const {
  std::lock_guard lock(mutex_);
  return active(lines_);
}

std::size_t Map::num_keyframes() const { return keyframes().size(); }
std::size_t Map::num_points() const { return points().size(); }
std::size_t Map::num_lines() const { return lines().size(); }

Map::Sizes Map::sizes() const {
  std::lock_guard lock(mutex_);
  return {keyframes_.size(), points_.size(), lines_.size()};
}

int Map::start_segment() {
  std::lock_guard lock(mutex_);
  segment_parent_.push_back(static_cast<int>(segment_parent_.size()));
  return segment_parent_.back();
}

int Map::segment_root(int s) const {
  while (segment_parent_.at(static_cast<std::size_t>(s)) != s) s = segment_parent_[static_cast<std::size_t>(s)];
  return s;
}

void Map::tie_segments(int a, int b) {
  std::lock_guard lock(mutex_);
  const int ra = segment_root(a), rb = segment_root(b);
  if (ra == rb) return;
  // The smaller root stays: segment 0 is always its set's root, so anchored() asks for root 0.
  segment_parent_[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  ++changes_;
}

bool Map::anchored(int segment) const {
  std::lock_guard lock(mutex_);
  return segment_root(segment) == 0;
}

int Map::num_segments() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(segment_parent_.size());
}

KeyFrame* Map::first_keyframe() const {
  std::lock_guard lock(mutex_);
  return all_keyframes_.empty() ? nullptr : all_keyframes_.front().get();
}

}  // namespace plslam::map
