#include "plslam/mapping/local_mapper.h"

#include "plslam/core/stopwatch.h"
#include "plslam/core/thread_priority.h"

#include <algorithm>
#include <chrono>

#include "plslam/place/keyframe_database.h"

namespace plslam::mapping {
namespace {

using Clock = std::chrono::steady_clock;

LocalMapperOptions with_shared_settings(LocalMapperOptions o) {
  o.ba.line_information = o.line_information;
  o.ba.far_stereo_baselines = o.far_stereo_baselines;
  o.ba.lines = o.lines;
  o.triangulation.lines = o.lines;
  return o;
}

}  // namespace

LocalMapper::LocalMapper(map::Map& map, LocalMapperOptions options)
    : map_(map), options_(with_shared_settings(options)), recent_(options_.recent) {}

LocalMapper::~LocalMapper() { stop(); }

void LocalMapper::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] {
    core::name_this_thread("plslam-mapping");
    run();
  });
}

void LocalMapper::stop() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_requested_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void LocalMapper::insert(map::KeyFrame* kf) {
  std::size_t waiting = 0;
  {
    std::lock_guard lock(queue_mutex_);
    queue_.push_back(kf);
    waiting = queue_.size();
    // With process_pending(), busy_ is never seen here: it runs in the inserting thread.
    if (busy_ && options_.abort_ba_on_new_keyframe) abort_ba_ = true;
  }
  cv_.notify_all();
  std::lock_guard stats_lock(stats_mutex_);
  stats_.max_queue = std::max(stats_.max_queue, static_cast<int>(waiting));
}

void LocalMapper::abort_ba() { abort_ba_ = true; }

void LocalMapper::pause() {
  const auto t0 = Clock::now();
  std::unique_lock lock(queue_mutex_);
  ++pauses_;
  if (busy_) abort_ba_ = true;
  cv_.wait(lock, [this] { return !busy_; });
  lock.unlock();
  std::lock_guard stats_lock(stats_mutex_);
  stats_.pause_wait_ms.push_back(ms_since(t0));
}

void LocalMapper::resume() {
  {
    std::lock_guard lock(queue_mutex_);
    --pauses_;
  }
  cv_.notify_all();
}

bool LocalMapper::idle() const {
  std::lock_guard lock(queue_mutex_);
  return queue_.empty() && !busy_ && !deferred_open_;
}

bool LocalMapper::try_pause() {
  std::lock_guard lock(queue_mutex_);
  // A deferred BA's window points at landmarks that reclamation would free.
  if (busy_ || !queue_.empty() || deferred_open_) return false;
  ++pauses_;
  return true;
}

std::size_t LocalMapper::queued() const {
  std::lock_guard lock(queue_mutex_);
  return queue_.size();
}

LocalMapperStats LocalMapper::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

void LocalMapper::wait_idle() {
  if (!thread_.joinable()) {
    process_pending();
    return;
  }
  std::unique_lock lock(queue_mutex_);
  cv_.wait(lock, [this] { return (queue_.empty() && !busy_) || stop_requested_; });
}

void LocalMapper::process_front(std::unique_lock<std::mutex>& lock, bool defer, bool in_caller) {
  map::KeyFrame* kf = queue_.front();
  queue_.pop_front();
  const bool more = !queue_.empty();
  busy_ = true;
  abort_ba_ = false;  // an abort meant for the previous keyframe's BA
  lock.unlock();
  finish_deferred();
  process(kf, more, defer, in_caller);
  lock.lock();
  busy_ = false;
  cv_.notify_all();
}

void LocalMapper::process_pending() {
  finish_deferred();
  std::unique_lock lock(queue_mutex_);
  while (!queue_.empty()) process_front(lock, false, true);
}

void LocalMapper::process_pending_deferring_ba() {
  std::unique_lock lock(queue_mutex_);
  while (!queue_.empty()) process_front(lock, true, true);
}

void LocalMapper::optimise_deferred_ba() {
  if (!deferred_ || deferred_->optimised) return;
  deferred_->optimised = true;
  if (!deferred_->window) return;
  const auto t0 = Clock::now();
  deferred_->result = solve_local_ba(*deferred_->window, *deferred_->kf, options_.ba, &abort_ba_);
  deferred_->processing_ms += ms_since(t0);
  deferred_->ba_ms += ms_since(t0);
}

std::size_t LocalMapper::deferred_ba_observations() const {
  if (!deferred_ || !deferred_->window) return 0;
  const auto& problem = deferred_->window->problem;
  return problem.point_observations.size() + problem.line_observations.size();
}

void LocalMapper::finish_deferred() {
  if (!deferred_) return;
  optimise_deferred_ba();
  Deferred d = std::move(*deferred_);
  deferred_.reset();
  {
    std::lock_guard lock(queue_mutex_);
    deferred_open_ = false;
  }
  const auto t0 = Clock::now();
  if (d.window && apply_local_ba(map_, *d.window, d.result)) {
    std::lock_guard lock(stats_mutex_);
    stats_.local_ba_ms.push_back(d.ba_ms + ms_since(t0));
    stats_.aborted_local_ba += d.result.aborted;
  }
  if (!d.more_waiting) cull_keyframes(d.kf);
  {
    std::lock_guard lock(stats_mutex_);
    stats_.keyframe_ms.push_back(d.processing_ms + ms_since(t0));
  }
  if (sink_ && !d.kf->is_bad()) sink_(d.kf);
}

void LocalMapper::run() {
  std::unique_lock lock(queue_mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return (!queue_.empty() && pauses_ == 0) || stop_requested_; });
    if (queue_.empty()) break;  // stop requested and nothing left
    if (pauses_ > 0) {  // a stop request while loop closing holds a pause: finish after it
      cv_.wait(lock, [this] { return pauses_ == 0; });
      continue;
    }
    process_front(lock);
  }
}

void LocalMapper::process(map::KeyFrame* kf, bool more_waiting, bool defer, bool in_caller) {
  const auto t0 = Clock::now();
  process_new_keyframe(kf);
  // The bag of words is computed here, off the tracking thread (ORB-SLAM2 does it in local mapping too).
  if (database_) database_->add(kf);
  recent_.cull(kf->id());
  auto t = Clock::now();
  triangulate(kf);
  const double triangulation_ms = ms_since(t);
  double fusion_ms = -1;
  const bool ba_due = options_.local_ba && map_.num_keyframes() > 2;
  // The mapping thread, which must catch up, skips a keyframe's fusion and BA while more wait
  // (ORB-SLAM2). In the caller's thread (deterministic mode) it is mapped in full, and its BA is
  // the last waiting keyframe's, with it free in that window.
  const bool catching_up = more_waiting && !in_caller;
  bool ba_skipped = ba_due && catching_up;
  Deferred d;
  d.kf = kf;
  d.more_waiting = catching_up;
  if (!catching_up) {
    t = Clock::now();
    fuse(kf);
    fusion_ms = ms_since(t);
    // An abort raised before the BA starts (a pause, a newer keyframe) skips it.
    ba_skipped = ba_due && abort_ba_;
    if (ba_due && !ba_skipped && more_waiting) {
      covered_.push_back(kf);
    } else if (ba_due && !ba_skipped) {
      t = Clock::now();
      d.window.emplace(local_ba_window(*kf, options_.ba, covered_));
      d.ba_ms = ms_since(t);
      if (d.window->problem.point_observations.empty()) d.window.reset();
    }
  }
  // The last of the waiting keyframes: its window covers the ones before it, or (an abort,
  // nothing to optimise) they go without a BA.
  int covered = 0;
  int uncovered = 0;
  if (!more_waiting) {
    (d.window ? covered : uncovered) = static_cast<int>(covered_.size());
    covered_.clear();
  }
  d.processing_ms = ms_since(t0);
  {
    std::lock_guard lock(stats_mutex_);
    stats_.skipped_local_ba += ba_skipped + uncovered;
    stats_.covered_local_ba += covered;
    stats_.triangulation_ms.push_back(triangulation_ms);
    if (fusion_ms >= 0) stats_.fusion_ms.push_back(fusion_ms);
  }
  deferred_ = std::move(d);
  {
    std::lock_guard lock(queue_mutex_);
    deferred_open_ = true;
  }
  if (!defer) finish_deferred();
}

void LocalMapper::process_new_keyframe(map::KeyFrame* kf) {
  const auto points = kf->map_points();
  for (std::size_t i = 0; i < points.size(); ++i) {
    map::MapPoint* mp = points[i];
    if (!mp) continue;
    // Culled since tracking associated it: a bad point must not stay in the slot, where it would
    // outlive reclamation (Map::reclaim).
    if (mp->is_bad()) {
      kf->erase_map_point(static_cast<int>(i));
      continue;
    }
    if (mp->index_in(kf) < 0) {
      if (!mp->add_observation(kf, static_cast<int>(i))) {
        kf->erase_map_point(static_cast<int>(i));
        continue;
      }
      mp->update_normal_and_depth();
      mp->update_descriptor();
    } else {
      recent_.add(mp, kf->id());  // created by this keyframe
    }
  }
  const auto lines = kf->map_lines();
  for (std::size_t j = 0; j < lines.size(); ++j) {
    map::MapLine* ml = lines[j];
    if (!ml) continue;
    if (ml->is_bad()) {
      kf->erase_map_line(static_cast<int>(j));
      continue;
    }
    if (ml->index_in(kf) < 0) {
      if (!ml->add_observation(kf, static_cast<int>(j))) {
        kf->erase_map_line(static_cast<int>(j));
        continue;
      }
      ml->update_normal_and_depth();
      ml->update_descriptor();
    } else {
      recent_.add(ml, kf->id());
    }
  }
  kf->update_connections();
}

void LocalMapper::triangulate(map::KeyFrame* kf) {
  const NewLandmarks made = triangulate_new_landmarks(map_, *kf, options_.triangulation);
  for (map::MapPoint* mp : made.points) recent_.add(mp, kf->id());
  for (map::MapLine* ml : made.lines) recent_.add(ml, kf->id());
  std::lock_guard lock(stats_mutex_);
  stats_.triangulated_points += static_cast<int>(made.points.size());
}

void LocalMapper::fuse(map::KeyFrame* kf) {
  const int fused = fuse_landmarks(*kf, options_.fusion);
  std::lock_guard lock(stats_mutex_);
  stats_.fused_points += fused;
}

void LocalMapper::cull_keyframes(map::KeyFrame* kf) {
  const auto culled = cull_redundant_keyframes(map_, *kf, options_.keyframe_culling, [this](map::KeyFrame* k) {
    if (database_) database_->erase(k);
  });
  std::lock_guard lock(stats_mutex_);
  stats_.culled_keyframes += static_cast<int>(culled.size());
}

}  // namespace plslam::mapping
