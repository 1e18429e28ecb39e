#include "plslam/loop/loop_closer.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/stopwatch.h"
#include "plslam/core/thread_priority.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/pose_only.h"
#include "plslam/place/bow_vector.h"

namespace plslam::loop {
namespace {

// How much lower the loop-closing and global-BA threads run than tracking and local mapping.
constexpr int kBackgroundNice = 5;
// The deterministic pipeline's global BA has seconds until its merge (loop.global_ba_merge_after_s):
// it takes what tracking and local mapping leave, so that they keep real time beside it.
constexpr int kDeferredGlobalBaNice = 19;

// Local mapping stays paused while this lives.
class MapperPause {
 public:
  explicit MapperPause(mapping::LocalMapper& m) : m_(m) { m_.pause(); }
  ~MapperPause() { m_.resume(); }
  MapperPause(const MapperPause&) = delete;
  MapperPause& operator=(const MapperPause&) = delete;

 private:
  mapping::LocalMapper& m_;
};

// A place: the keyframe and its covisible keyframes.
std::vector<map::KeyFrame*> place_of(map::KeyFrame* kf) {
  auto v = kf->covisibles();
  v.insert(v.begin(), kf);
  return v;
}

map::IdSet<map::KeyFrame> covisible_set(const map::KeyFrame& kf) {
  const auto v = kf.covisibles();
  return {v.begin(), v.end()};
}

// Whether a covisible keyframe of `kf` lies in `neighbourhood`: the two places are already tied
// (an earlier loop's fusion, or tracking that relocalized there).
bool touches(const map::IdSet<map::KeyFrame>& neighbourhood, const map::KeyFrame& kf) {
  const auto group = kf.covisibles();
  return std::any_of(group.begin(), group.end(), [&](map::KeyFrame* g) { return neighbourhood.count(g) > 0; });
}

}  // namespace

void LoopClosingOptions::validate() const {
  detector.validate();
  verifier.validate();
  across_verifier.validate();
  correction.graph.validate();
  if (min_projection_inliers < verifier.min_inliers) {
    throw std::invalid_argument("loop.min_projection_inliers: must be >= loop.min_inliers");
  }
  if (!(max_drift_ratio >= 0)) throw std::invalid_argument("loop.max_drift_ratio: must be >= 0");
  if (!(min_drift_m >= 0)) throw std::invalid_argument("loop.min_drift_m: must be >= 0");
  if (!(max_drift_deg > 0)) throw std::invalid_argument("loop.max_drift_deg: must be positive");
  if (!(projection_radius > 0)) throw std::invalid_argument("loop.projection_radius: must be positive");
  if (keyframes_between_loops < 0) throw std::invalid_argument("loop.keyframes_between_loops: must be >= 0");
  global_ba_options.validate();
  if (!(finish_wait_s >= 0)) throw std::invalid_argument("loop.finish_wait_s: must be >= 0");
  if (!(global_ba_merge_after_s >= 0)) throw std::invalid_argument("loop.global_ba_merge_after_s: must be >= 0");
  if (correction_merge_after_frames < 1) {
    throw std::invalid_argument("loop.correction_merge_after_frames: must be >= 1");
  }
}

LoopCloser::LoopCloser(map::Map& map, const place::KeyframeDatabase& database, mapping::LocalMapper& mapper,
                       LoopClosingOptions options)
    : map_(map), database_(database), mapper_(mapper), options_(std::move(options)),
      detector_(database, options_.detector) {
  options_.validate();
}

LoopCloser::~LoopCloser() {
  stop();
  abort_global_ba();
  if (graph_thread_.joinable()) graph_thread_.join();
}

void LoopCloser::start() {
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void LoopCloser::stop() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_requested_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void LoopCloser::insert(map::KeyFrame* kf) {
  {
    std::lock_guard lock(queue_mutex_);
    queue_.push_back(kf);
  }
  cv_.notify_all();
}

void LoopCloser::global_ba_after_keyframe(long keyframe_id, long before_loss_keyframe_id) {
  if (!options_.global_ba || !options_.global_ba_after_relocalization) return;
  revisit_from_ = options_.loop_across_relocalization ? before_loss_keyframe_id : -1;
  revisit_keyframe_ = keyframe_id;
}

void LoopCloser::refine_inertial_after_keyframe(long keyframe_id) {
  if (!options_.global_ba || !options_.global_ba_options.T_imu_cam) return;
  refine_keyframe_ = keyframe_id;
}

void LoopCloser::serve_inertial_refinement(const map::KeyFrame& kf, bool loop_closed) {
  long at = refine_keyframe_;
  if (at < 0 || kf.id() < at || !refine_keyframe_.compare_exchange_strong(at, -1)) return;
  if (loop_closed) return;  // the loop's global BA refines the same
  spdlog::info("global BA to refine the IMU's initialisation: keyframe {} (frame {})", kf.id(), kf.frame_id());
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.global_ba_inertial_refinements;
  }
  gba_requested_ = true;
  // Deferred, the caller starts it where nothing writes the map.
  if (!options_.defer_loop_correction) start_requested_global_ba();
}

bool LoopCloser::try_pause() {
  std::lock_guard lock(queue_mutex_);
  // A loop waiting for its correction holds keyframes and landmarks that reclamation would free.
  if (busy_ || !queue_.empty() || pending_loop_ || open_correction_) return false;
  {
    std::lock_guard gba_lock(gba_mutex_);
    if (gba_running_) return false;
  }
  ++pauses_;
  return true;
}

void LoopCloser::resume() {
  {
    std::lock_guard lock(queue_mutex_);
    --pauses_;
  }
  cv_.notify_all();
}

void LoopCloser::process_pending() {
  std::unique_lock lock(queue_mutex_);
  while (!queue_.empty()) {
    map::KeyFrame* kf = queue_.front();
    queue_.pop_front();
    lock.unlock();
    process(kf);
    lock.lock();
  }
}

void LoopCloser::wait_idle() {
  if (!thread_.joinable()) {
    process_pending();
    return;
  }
  std::unique_lock lock(queue_mutex_);
  cv_.wait(lock, [this] { return (queue_.empty() && !busy_) || stop_requested_; });
}

bool LoopCloser::finish() {
  wait_idle();
  settle_deferred_steps();
  std::unique_lock lock(gba_mutex_);
  const bool deferred = options_.defer_global_ba_merge;
  const bool done = gba_cv_.wait_for(lock, std::chrono::duration<double>(options_.finish_wait_s),
                                     [&] { return !gba_running_ || (deferred && gba_computed_); });
  lock.unlock();
  if (deferred && done) merge_deferred_global_ba();
  if (!done) {
    spdlog::warn("global BA still running after {:.0f} s: aborted; the outputs use the map as the loop correction left it",
                 options_.finish_wait_s);
  }
  abort_global_ba();
  return done;
}

void LoopCloser::abort_global_ba() {
  if (!gba_thread_.joinable()) return;
  gba_abort_ = true;
  gba_thread_.join();
  gba_abort_ = false;
  if (!deferred_) return;
  deferred_.reset();
  spdlog::info("global BA dropped before its merge");
  {
    std::lock_guard lock(gba_mutex_);
    gba_running_ = false;
  }
  gba_cv_.notify_all();
  std::lock_guard lock(stats_mutex_);
  ++stats_.global_ba_aborted;
}

void LoopCloser::start_deferred_global_ba() {
  deferred_ = std::make_unique<Deferred>();
  deferred_->t0 = std::chrono::steady_clock::now();
  deferred_->snapshot = snapshot_for_global_ba(map_, options_.global_ba_options);
  spdlog::debug("global BA snapshot: {} keyframes, {:.1f} ms", deferred_->snapshot.problem->keyframes.size(),
                ms_since(deferred_->t0));
  {
    std::lock_guard lock(gba_mutex_);
    gba_running_ = true;
    gba_computed_ = false;
  }
  ++gba_starts_;
  gba_thread_ = std::thread([this, d = deferred_.get()] {
    core::lower_this_thread_priority(kDeferredGlobalBaNice);
    core::name_this_thread("plslam-gba");
    d->result = run_global_ba(d->snapshot, options_.global_ba_options, &gba_abort_);
    {
      std::lock_guard lock(gba_mutex_);
      gba_computed_ = true;
    }
    gba_cv_.notify_all();
  });
}

bool LoopCloser::merge_deferred_global_ba() {
  if (!gba_thread_.joinable()) return false;
  gba_thread_.join();
  auto d = std::move(deferred_);
  {
    std::lock_guard lock(gba_mutex_);
    gba_running_ = false;
  }
  gba_cv_.notify_all();
  return d && merge_into_map(d->snapshot, d->result, d->t0);
}

void LoopCloser::global_ba() {
  const auto t0 = std::chrono::steady_clock::now();
  GlobalBaSnapshot snapshot;
  {
    // Local mapping is the only writer of poses and positions besides loop closing.
    MapperPause pause(mapper_);
    snapshot = snapshot_for_global_ba(map_, options_.global_ba_options);
  }
  auto result = run_global_ba(snapshot, options_.global_ba_options, &gba_abort_);
  result.aborted = result.aborted || gba_abort_;
  merge_into_map(snapshot, result, t0);
}

bool LoopCloser::merge_into_map(const GlobalBaSnapshot& snapshot, const optim::BaResult& result,
                                std::chrono::steady_clock::time_point t0) {
  if (result.aborted || !result.usable) {
    spdlog::info("global BA {}", result.usable ? "aborted" : "unusable: " + result.message);
    std::lock_guard lock(stats_mutex_);
    ++stats_.global_ba_aborted;
    return false;
  }
  GlobalBaMergeStats merged;
  {
    // Deferred, the caller merges with local mapping at rest; otherwise it is held here.
    std::optional<MapperPause> pause;
    if (!options_.defer_global_ba_merge) pause.emplace(mapper_);
    std::lock_guard map_lock(map_.update_mutex());
    merged = merge_global_ba(map_, snapshot, result);
  }
  const double ms = ms_since(t0);
  spdlog::info("global BA: {} keyframes, {} points, {} lines, {} iterations, cost {:.4g} -> {:.4g}; merged with {} new "
               "keyframes; {:.0f} ms",
               merged.keyframes, merged.points, merged.lines, result.iterations, result.initial_cost, result.final_cost,
               merged.propagated_keyframes, ms);
  std::lock_guard lock(stats_mutex_);
  stats_.global_ba_ms.push_back(ms);
  ++stats_.global_ba_runs;
  return true;
}

LoopClosingStats LoopCloser::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

void LoopCloser::run() {
  // Loop closing can wait; tracking cannot (a corrected loop is worth the same a frame later).
  core::lower_this_thread_priority(kBackgroundNice);
  core::name_this_thread("plslam-loop");
  std::unique_lock lock(queue_mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return (!queue_.empty() && pauses_ == 0) || stop_requested_; });
    if (queue_.empty()) break;
    if (pauses_ > 0) {
      cv_.wait(lock, [this] { return pauses_ == 0; });
      continue;
    }
    map::KeyFrame* kf = queue_.front();
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    process(kf);
    lock.lock();
    busy_ = false;
    cv_.notify_all();
  }
}

std::optional<LoopConstraint> LoopCloser::confirm(map::KeyFrame* kf, const LoopDetection& d,
                                                  const LoopVerifierOptions& verifier, long path_from) {
  auto c = verify_loop(kf, d.keyframe, database_, verifier);
  if (!c) return std::nullopt;
  // The place's map points, projected into the keyframe with the verified pose, give more
  // matches; the keyframe's pose refined over all their reprojection errors must keep enough.
  const auto& qd = kf->data();
  const geometry::SE3 T_cw = d.keyframe->pose();
  geometry::SE3 T_qw = (c->T_query_candidate * T_cw).normalized();
  std::vector<map::MapPoint*> matched(qd.keypoints.size(), nullptr);  // place point per query keypoint
  map::IdSet<map::MapPoint> used;
  for (const auto& [qp, cp] : c->matches) {
    const int i = qp->index_in(kf);
    if (i >= 0 && used.insert(cp).second) matched[static_cast<std::size_t>(i)] = cp;
  }
  mapping::ProjectionMatchOptions pm;
  pm.point_radius = options_.projection_radius;
  pm.point_chi2 = options_.projection_radius * options_.projection_radius;
  const Eigen::Vector3d O = T_qw.inverse().translation();
  map::IdSet<map::MapPoint> place_points;
  for (map::KeyFrame* k : place_of(d.keyframe)) {
    for (map::MapPoint* p : k->map_points()) {
      if (p && !p->is_bad()) place_points.insert(p);
    }
  }
  for (map::MapPoint* p : place_points) {
    if (used.count(p)) continue;
    const int j = mapping::match_point_in_keyframe(*kf, T_qw, O, *p, pm);
    if (j < 0 || matched[static_cast<std::size_t>(j)]) continue;
    matched[static_cast<std::size_t>(j)] = p;
    used.insert(p);
  }
  std::vector<optim::PosePointTerm> terms;
  std::vector<std::size_t> term_keypoint;
  for (std::size_t i = 0; i < matched.size(); ++i) {
    if (!matched[i]) continue;
    terms.push_back({matched[i]->position(), qd.point_observation(i)});
    term_keypoint.push_back(i);
  }
  if (static_cast<int>(terms.size()) < options_.min_projection_inliers) {
    spdlog::debug("loop: keyframe {} -> {}: {} matches after the projection search, rejected", kf->id(),
                  d.keyframe->id(), terms.size());
    return std::nullopt;
  }
  optim::PoseOnlyOptions po;
  po.scale_factor = qd.scale_factor;
  const auto refined = optim::optimize_pose(geometry::StereoCamera(qd.calib), T_qw, terms, {}, po);
  if (refined.num_point_inliers < options_.min_projection_inliers) {
    spdlog::debug("loop: keyframe {} -> {}: {} of {} projected matches after refinement, rejected", kf->id(),
                  d.keyframe->id(), refined.num_point_inliers, terms.size());
    return std::nullopt;
  }
  c->T_query_candidate = (refined.T_cw * T_cw.inverse()).normalized();
  if (!plausible(kf, d.keyframe, refined.T_cw, path_from >= 0 ? path_from : d.keyframe->id())) return std::nullopt;
  // The matches to fuse: the refinement's inliers whose keypoint already has a map point.
  const auto q_points = kf->map_points();
  c->matches.clear();
  for (std::size_t t = 0; t < terms.size(); ++t) {
    if (refined.point_outlier[t]) continue;
    map::MapPoint* qp = q_points[term_keypoint[t]];
    if (qp && !qp->is_bad()) c->matches.emplace_back(qp, matched[term_keypoint[t]]);
  }
  c->inliers = refined.num_point_inliers;
  return c;
}

bool LoopCloser::plausible(map::KeyFrame* query, map::KeyFrame* candidate, const geometry::SE3& T_qw_corrected,
                           long path_from) {
  // The path the keyframes travelled from the place to the query, in keyframe order.
  double path = 0;
  const map::KeyFrame* previous = nullptr;
  for (map::KeyFrame* k : map_.keyframes()) {
    if (k->id() < path_from || k->id() > query->id()) continue;
    if (previous) path += (k->camera_center() - previous->camera_center()).norm();
    previous = k;
  }
  const geometry::SE3 T_qw = query->pose();
  const double moved = (T_qw_corrected.inverse().translation() - T_qw.inverse().translation()).norm();
  const double turned = Eigen::AngleAxisd((T_qw_corrected * T_qw.inverse()).rotation()).angle() * 180 / M_PI;
  const double bound = options_.max_drift_ratio * path + options_.min_drift_m;
  if (moved <= bound && turned <= options_.max_drift_deg) return true;
  spdlog::debug("loop candidate rejected: keyframe {} (frame {}) -> {} (frame {}) would move it {:.2f} m and turn it {:.1f} "
               "deg after {:.1f} m of path (bounds {:.2f} m, {:.0f} deg)",
               query->id(), query->frame_id(), candidate->id(), candidate->frame_id(), moved, turned, path, bound,
               options_.max_drift_deg);
  std::lock_guard lock(stats_mutex_);
  ++stats_.implausible;
  return false;
}

void LoopCloser::process(map::KeyFrame* kf) {
  const bool loop_closed = close_loop(kf);
  serve_inertial_refinement(*kf, loop_closed);
  long revisit = revisit_keyframe_;
  if (revisit < 0 || kf->id() < revisit) return;
  // Tracking may have asked again meanwhile (a second relocalization): that one waits for its own
  // keyframe.
  if (!revisit_keyframe_.compare_exchange_strong(revisit, -1)) return;
  if (loop_closed) return;  // the loop starts its own global BA
  const long before = revisit_from_.exchange(-1);
  if (before >= 0 && close_loop_across_relocalization(kf, before)) return;
  spdlog::info("global BA after the relocalized revisit: keyframe {} (frame {})", kf->id(), kf->frame_id());
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.global_ba_after_relocalization;
  }
  gba_requested_ = true;
  // Deferred, the caller starts it where nothing writes the map.
  if (!options_.defer_loop_correction) start_requested_global_ba();
}

bool LoopCloser::close_loop(map::KeyFrame* kf) {
  if (kf->is_bad()) return false;
  // A loop corrected while this keyframe waited in the queue may have fused its points into the
  // place's: its covisibility must say so before the detector and the guard below read it.
  if (map_.big_changes() > 0 && !options_.defer_loop_correction) kf->update_connections();
  const auto detections = detector_.detect(kf);
  if (detections.empty()) return false;
  if (last_loop_keyframe_ >= 0 && kf->id() < last_loop_keyframe_ + options_.keyframes_between_loops) return false;
  // Local BA moves the keyframes and points the verification compares: pause it from here on.
  MapperPause pause(mapper_);
  if (kf->is_bad()) return false;
  std::optional<LoopConstraint> loop;
  int rejected = 0;
  // A place the keyframe's neighbourhood already shares keyframes with is already tied to it (an
  // earlier loop's fusion, or tracking that relocalized there): correcting it again would only
  // move the map by the noise of a second estimate.
  const auto neighbourhood = covisible_set(*kf);
  for (const auto& d : detections) {
    if (d.keyframe->is_bad() || touches(neighbourhood, *d.keyframe)) continue;
    loop = confirm(kf, d, options_.verifier);
    if (loop) break;
    ++rejected;
  }
  {
    std::lock_guard lock(stats_mutex_);
    stats_.detections += static_cast<int>(detections.size());
    stats_.rejected += rejected;
  }
  if (!loop) return false;
  correct(*loop, kf);
  return true;
}

// Keyframes of the revisit's place verified against the one before the loss, most similar first.
constexpr std::size_t kAcrossRelocalizationCandidates = 3;

bool LoopCloser::close_loop_across_relocalization(map::KeyFrame* kf, long before_id) {
  map::KeyFrame* before = nullptr;
  for (map::KeyFrame* k : map_.keyframes()) {
    if (k->id() == before_id) before = k;
  }
  if (!before) return false;
  MapperPause pause(mapper_);
  if (before->is_bad() || kf->is_bad()) return false;
  // A relocalization that continued the trusted trajectory left the two in one neighbourhood.
  auto neighbourhood = covisible_set(*before);
  neighbourhood.insert(before);
  if (neighbourhood.count(kf) || touches(neighbourhood, *kf)) return false;
  // The drift to correct is that of the path since the place was seen: from the oldest keyframe
  // of the revisit's neighbourhood (where relocalization put the camera) to the one before the loss.
  const auto revisit = place_of(kf);
  long place = kf->id();
  for (map::KeyFrame* g : revisit) place = std::min(place, g->id());
  // The candidates: the revisit's keyframe and its neighbourhood, the most similar to the keyframe
  // before the loss first (the camera moved on during the loss, so another view of the place may
  // overlap it more).
  const auto description = database_.description(before);
  if (!description) return false;
  std::vector<std::pair<double, map::KeyFrame*>> candidates;
  for (map::KeyFrame* c : revisit) {
    const auto d = database_.description(c);
    if (!d || c->is_bad()) continue;
    candidates.emplace_back(place::l1_score(description->bow, d->bow), c);
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  if (candidates.size() > kAcrossRelocalizationCandidates) candidates.resize(kAcrossRelocalizationCandidates);
  std::optional<LoopConstraint> loop;
  for (const auto& [score, c] : candidates) {
    loop = confirm(before, LoopDetection{c, score, 0}, options_.across_verifier, place);
    if (loop) break;
  }
  {
    std::lock_guard lock(stats_mutex_);
    stats_.detections += static_cast<int>(candidates.size());
    stats_.rejected += static_cast<int>(candidates.size()) - (loop ? 1 : 0);
  }
  spdlog::info("loop across the relocalization: keyframe {} (frame {}, before the loss) -> {}", before->id(),
               before->frame_id(),
               loop ? fmt::format("keyframe {} (frame {}) verified", loop->candidate->id(), loop->candidate->frame_id())
                    : fmt::format("none of {} keyframes of the revisit's place verified", candidates.size()));
  if (!loop) return false;
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.loops_across_relocalization;
  }
  correct(*loop, kf);
  return true;
}

void LoopCloser::correct(const LoopConstraint& loop, map::KeyFrame* newest) {
  map::KeyFrame* kf = loop.query;
  detector_.reset();
  last_loop_keyframe_ = std::max(kf->id(), newest->id());
  if (options_.defer_loop_correction) {
    pending_loop_ = loop;
    return;
  }
  abort_global_ba();  // its snapshot predates this loop
  const auto t0 = std::chrono::steady_clock::now();
  LoopCorrectionResult result;
  {
    std::lock_guard map_lock(map_.update_mutex());
    result = correct_loop(map_, loop, options_.correction);
    // A loop into an anchored segment brings a new segment's keyframes into the map's frame.
    map_.tie_segments(kf->segment(), loop.candidate->segment());
  }
  corrected(loop, result, ms_since(t0));
}

std::size_t LoopCloser::queued() const {
  std::lock_guard lock(queue_mutex_);
  return queue_.size();
}

void LoopCloser::refresh_queued_connections() {
  if (map_.big_changes() == 0) return;
  std::lock_guard lock(queue_mutex_);
  for (map::KeyFrame* kf : queue_) {
    if (!kf->is_bad()) kf->update_connections();
  }
}

void LoopCloser::start_requested_global_ba() {
  if (!gba_requested_) return;
  gba_requested_ = false;
  abort_global_ba();  // an older one's snapshot predates the revisit or loop that asked for this one
  start_global_ba();
}

void LoopCloser::begin_deferred_correction() {
  if (!pending_loop_) return;
  const LoopConstraint loop = std::move(*pending_loop_);
  pending_loop_.reset();
  if (loop.query->is_bad() || loop.candidate->is_bad()) {
    spdlog::info("loop dropped before its correction: keyframe {} or {} was culled meanwhile", loop.query->id(),
                 loop.candidate->id());
    return;
  }
  abort_global_ba();  // its snapshot predates this loop
  gba_requested_ = false;  // ... and so would one asked for before it
  const auto t0 = std::chrono::steady_clock::now();
  auto open = std::make_unique<OpenCorrection>();
  open->loop = loop;
  {
    std::lock_guard map_lock(map_.update_mutex());
    open->plan = begin_loop_correction(map_, loop, options_.correction);
    map_.note_big_change();  // tracking's last frame moves with its reference keyframe
  }
  open->begin_ms = ms_since(t0);
  open_correction_ = std::move(open);
  graph_thread_ = std::thread([this, o = open_correction_.get()] {
    core::name_this_thread("plslam-graph");
    const auto t = std::chrono::steady_clock::now();
    o->graph = solve_essential_graph(o->plan.problem, options_.correction.graph);
    o->graph_ms = ms_since(t);
  });
}

void LoopCloser::finish_deferred_correction() {
  if (!open_correction_) return;
  graph_thread_.join();
  auto open = std::move(open_correction_);
  abort_global_ba();  // one a revisit asked for meanwhile predates this loop's end
  const auto t0 = std::chrono::steady_clock::now();
  LoopCorrectionResult result;
  {
    std::lock_guard map_lock(map_.update_mutex());
    result = finish_loop_correction(map_, open->plan, std::move(open->graph));
    map_.tie_segments(open->loop.query->segment(), open->loop.candidate->segment());
  }
  const double ms = open->begin_ms + ms_since(t0);
  spdlog::debug("loop correction beside tracking: {:.0f} ms to begin, essential graph {:.0f} ms in its thread, "
                "{:.0f} ms to finish", open->begin_ms, open->graph_ms, ms - open->begin_ms);
  corrected(open->loop, result, ms);
}

void LoopCloser::settle_deferred_steps() {
  begin_deferred_correction();
  finish_deferred_correction();
  start_requested_global_ba();
}

void LoopCloser::corrected(const LoopConstraint& loop, const LoopCorrectionResult& result, double ms) {
  map::KeyFrame* kf = loop.query;
  LoopRecord rec;
  rec.frame = kf->frame_id();
  rec.keyframe = kf->id();
  rec.matched_keyframe = loop.candidate->id();
  rec.matched_frame = loop.candidate->frame_id();
  rec.inliers = loop.inliers;
  rec.fused_points = result.fused_points;
  rec.fused_lines = result.fused_lines;
  rec.correction_ms = ms;
  spdlog::info("loop closed: frame {} (keyframe {}) -> frame {} (keyframe {}), {} inliers, fused {} points and {} "
               "lines, {} loop edges, {} keyframes still queued for mapping moved along, {:.0f} ms",
               rec.frame, rec.keyframe, rec.matched_frame, rec.matched_keyframe, rec.inliers, rec.fused_points,
               rec.fused_lines, result.graph.loop_edges, result.unmapped_keyframes, ms);
  {
    std::lock_guard lock(stats_mutex_);
    stats_.loops.push_back(rec);
  }
  if (!options_.global_ba) return;
  if (options_.defer_loop_correction) {
    gba_requested_ = true;  // the caller starts it at its next step
    return;
  }
  start_global_ba();
}

void LoopCloser::start_global_ba() {
  if (options_.defer_global_ba_merge) {
    start_deferred_global_ba();
    return;
  }
  if (!thread_.joinable()) {  // sequential: in the caller, for reproducible runs
    global_ba();
    return;
  }
  {
    std::lock_guard lock(gba_mutex_);
    gba_running_ = true;
  }
  gba_thread_ = std::thread([this] {
    core::lower_this_thread_priority(kBackgroundNice);
    core::name_this_thread("plslam-gba");
    global_ba();
    {
      std::lock_guard lock(gba_mutex_);
      gba_running_ = false;
    }
    gba_cv_.notify_all();
  });
}

}  // namespace plslam::loop
