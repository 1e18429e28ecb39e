#include "plslam/mapping/local_mapper.h"

#include "plslam/core/stopwatch.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include <spdlog/spdlog.h>

#include "plslam/features/orb_descriptor.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/geometry/triangulation.h"
#include "plslam/map/descriptor_utils.h"
#include "plslam/mapping/epipolar_index.h"
#include "plslam/mapping/keyframe_projection.h"
#include "plslam/mapping/map_ba_problem.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::mapping {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Epipolar = 3.84;  // 1 DoF, 95 %: distance of a keypoint to its epipolar line

}  // namespace

LocalMapper::LocalMapper(map::Map& map, LocalMapperOptions options) : map_(map), options_(options) {}

LocalMapper::~LocalMapper() { stop(); }

void LocalMapper::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
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
  {
    std::lock_guard lock(queue_mutex_);
    queue_.push_back(kf);
  }
  cv_.notify_all();
}

void LocalMapper::pause() {
  std::unique_lock lock(queue_mutex_);
  ++pauses_;
  cv_.wait(lock, [this] { return !busy_; });
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
  return queue_.empty() && !busy_;
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

void LocalMapper::process_front(std::unique_lock<std::mutex>& lock) {
  map::KeyFrame* kf = queue_.front();
  queue_.pop_front();
  const bool more = !queue_.empty();
  busy_ = true;
  lock.unlock();
  process(kf, more);
  lock.lock();
  busy_ = false;
  cv_.notify_all();
}

void LocalMapper::process_pending() {
  std::unique_lock lock(queue_mutex_);
  while (!queue_.empty()) process_front(lock);
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

void LocalMapper::process(map::KeyFrame* kf, bool more_waiting) {
  const auto t0 = Clock::now();
  process_new_keyframe(kf);
  // The bag of words is computed here, off the tracking thread (ORB-SLAM2 does it in local mapping too).
  if (database_) database_->add(kf);
  cull_recent(kf);
  auto t = Clock::now();
  triangulate(kf);
  const double triangulation_ms = ms_since(t);
  double fusion_ms = -1;
  // Like ORB-SLAM2: the expensive steps only when tracking is not waiting with more keyframes.
  if (!more_waiting) {
    t = Clock::now();
    fuse(kf);
    fusion_ms = ms_since(t);
    if (options_.local_ba && map_.num_keyframes() > 2) local_bundle_adjustment(kf);
    cull_keyframes(kf);
  }
  {
    std::lock_guard lock(stats_mutex_);
    stats_.keyframe_ms.push_back(ms_since(t0));
    stats_.triangulation_ms.push_back(triangulation_ms);
    if (fusion_ms >= 0) stats_.fusion_ms.push_back(fusion_ms);
  }
  if (sink_ && !kf->is_bad()) sink_(kf);
}

void LocalMapper::process_new_keyframe(map::KeyFrame* kf) {
  const auto points = kf->map_points();
  for (std::size_t i = 0; i < points.size(); ++i) {
    map::MapPoint* mp = points[i];
    if (!mp || mp->is_bad()) continue;
    if (mp->index_in(kf) < 0) {
      mp->add_observation(kf, static_cast<int>(i));
      mp->update_normal_and_depth();
      mp->update_descriptor();
    } else {
      recent_points_.emplace_back(mp, kf->id());  // created by this keyframe
    }
  }
  const auto lines = kf->map_lines();
  for (std::size_t j = 0; j < lines.size(); ++j) {
    map::MapLine* ml = lines[j];
    if (!ml || ml->is_bad()) continue;
    if (ml->index_in(kf) < 0) {
      ml->add_observation(kf, static_cast<int>(j));
      ml->update_normal_and_depth();
      ml->update_descriptor();
    } else {
      recent_lines_.emplace_back(ml, kf->id());
    }
  }
  kf->update_connections();
}

void LocalMapper::cull_recent(map::KeyFrame* kf) {
  // ORB-SLAM2's MapPointCulling for stereo: a new landmark must be found in >= 25 % of the frames
  // that should see it, and have an observation weight above 3 (two stereo keyframes, or three
  // keyframes of which one stereo) once 2 more keyframes have passed.
  constexpr int kMaxWeightCulled = 3;
  auto cull = [&](auto& recent, auto too_few_observations) {
    for (auto it = recent.begin(); it != recent.end();) {
      auto* lm = it->first;
      const long age = kf->id() - it->second;
      if (lm->is_bad()) {
        it = recent.erase(it);
      } else if (lm->found_ratio() < 0.25 || (age >= 2 && too_few_observations(*lm))) {
        lm->set_bad();
        it = recent.erase(it);
      } else if (age >= 3) {
        it = recent.erase(it);
      } else {
        ++it;
      }
    }
  };
  cull(recent_points_, [](const map::MapPoint& p) { return p.observation_weight() <= kMaxWeightCulled; });
  // Lines keep the stricter rule, three observing keyframes: a stereo line's depth is far less
  // certain than a stereo point's (endpoints slide along the epipolar direction), and on the
  // rendered street and corridor the weight rule kept 4-20x more lines and raised the ATE.
  cull(recent_lines_, [](const map::MapLine& l) { return l.num_observations() < 3; });
}

void LocalMapper::triangulate(map::KeyFrame* kf) {
  const auto& d1 = kf->data();
  const geometry::StereoCamera cam(d1.calib);
  const geometry::SE3 T1 = kf->pose();
  const Eigen::Vector3d O1 = kf->camera_center();
  const auto points1 = kf->map_points();
  int created = 0;
  for (map::KeyFrame* kf2 : kf->best_covisibles(static_cast<std::size_t>(options_.triangulation_neighbors))) {
    const auto& d2 = kf2->data();
    const geometry::SE3 T2 = kf2->pose();
    const Eigen::Vector3d O2 = kf2->camera_center();
    // Below the stereo baseline, two-view triangulation adds nothing to the stereo depth.
    if ((O2 - O1).norm() < d1.calib.baseline) continue;
    const auto points2 = kf2->map_points();
    // Fundamental matrix F12 (x1^T F12 x2 = 0) from the relative pose, for the epipolar check.
    const geometry::SE3 T12 = T1 * T2.inverse();
    const Eigen::Matrix3d R12 = T12.rotation();
    const Eigen::Vector3d t12 = T12.translation();
    Eigen::Matrix3d K;
    K << d1.calib.fx, 0, d1.calib.cx, 0, d1.calib.fy, d1.calib.cy, 0, 0, 1;
    const Eigen::Matrix3d Kinv = K.inverse();
    const Eigen::Matrix3d F12 = Kinv.transpose() * geometry::hat(t12) * R12 * Kinv;
    // Free keypoints of kf2, indexed per level around the epipole (camera 1's centre seen from
    // camera 2), so that each level is searched with its own band.
    const geometry::SE3 T21 = T12.inverse();
    const Eigen::Vector3d epipole = K * T21.translation();
    const Eigen::Matrix3d H21 = K * T21.rotation() * Kinv;  // x1 -> image-2 direction of its ray
    std::vector<std::vector<int>> free2(static_cast<std::size_t>(d2.levels));
    std::vector<std::vector<Eigen::Vector2d>> free2_position(free2.size());
    for (std::size_t j = 0; j < points2.size(); ++j) {
      if (points2[j]) continue;
      const auto level = static_cast<std::size_t>(std::clamp(d2.keypoints[j].octave, 0, d2.levels - 1));
      free2[level].push_back(static_cast<int>(j));
      free2_position[level].emplace_back(d2.keypoints[j].pt.x, d2.keypoints[j].pt.y);
    }
    std::vector<EpipolarIndex> index;
    std::vector<double> band;  // the epipolar test's gate below, plus rounding
    for (std::size_t l = 0; l < free2.size(); ++l) {
      index.emplace_back(free2_position[l], epipole);
      band.push_back(std::sqrt(kChi2Epipolar * d2.level_sigma2(static_cast<int>(l))) + 1e-6);
    }
    std::vector<int> candidates;
    std::vector<bool> used2(points2.size(), false);
    for (std::size_t i = 0; i < points1.size(); ++i) {
      if (points1[i] || kf->map_point(static_cast<int>(i))) continue;
      const auto& kp1 = d1.keypoints[i];
      const Eigen::Vector3d x1(kp1.pt.x, kp1.pt.y, 1.0);
      const Eigen::Vector3d epiline = F12.transpose() * x1;  // line in image 2
      const double norm = std::hypot(epiline.x(), epiline.y());
      int best = 50, best_j = -1;  // ORB-SLAM2's TH_LOW
      EpipolarIndex::Ray ray;
      const bool has_ray = index.front().ray(H21 * x1, &ray);
      for (std::size_t l = 0; l < index.size(); ++l) {
        if (free2[l].empty()) continue;
        if (has_ray) {
          index[l].query(ray, band[l], &candidates);
        } else {
          index[l].query_all(&candidates);
        }
        for (int c : candidates) {
          const int j = free2[l][static_cast<std::size_t>(c)];
          if (used2[static_cast<std::size_t>(j)]) continue;
          const auto& kp2 = d2.keypoints[static_cast<std::size_t>(j)];
          const double dist_epi = std::abs(epiline.x() * kp2.pt.x + epiline.y() * kp2.pt.y + epiline.z()) / norm;
          if (dist_epi * dist_epi > kChi2Epipolar * d2.level_sigma2(kp2.octave)) continue;
          const int h = features::hamming_distance(d1.descriptors.ptr<uint8_t>(static_cast<int>(i)),
                                                   d2.descriptors.ptr<uint8_t>(j));
          if (h < best || (h == best && j < best_j)) {  // ties: the lowest index, whatever the query order
            best = h;
            best_j = j;
          }
        }
      }
      if (best_j < 0) continue;
      const auto& kp2 = d2.keypoints[static_cast<std::size_t>(best_j)];
      // Enough parallax, otherwise stereo depth already did better.
      const Eigen::Vector3d r1 = T1.rotation().transpose() * (Kinv * x1);
      const Eigen::Vector3d r2 = T2.rotation().transpose() * (Kinv * Eigen::Vector3d(kp2.pt.x, kp2.pt.y, 1.0));
      if (r1.normalized().dot(r2.normalized()) > 0.9998) continue;
      const auto X = geometry::triangulate_point(cam, T1, T2, {kp1.pt.x, kp1.pt.y}, {kp2.pt.x, kp2.pt.y});
      if (!X) continue;
      const Eigen::Vector3d Xc1 = T1 * *X, Xc2 = T2 * *X;
      if (Xc1.z() <= 0 || Xc2.z() <= 0) continue;
      if ((cam.project(Xc1) - Eigen::Vector2d(kp1.pt.x, kp1.pt.y)).squaredNorm() > kChi2Mono * d1.level_sigma2(kp1.octave)) continue;
      if ((cam.project(Xc2) - Eigen::Vector2d(kp2.pt.x, kp2.pt.y)).squaredNorm() > kChi2Mono * d2.level_sigma2(kp2.octave)) continue;
      // Scale consistency: the distance ratio must agree with the octave ratio.
      const double ratio_dist = (*X - O2).norm() / std::max((*X - O1).norm(), 1e-9);
      const double ratio_octave = d1.level_scale(kp1.octave) / d2.level_scale(kp2.octave);
      if (ratio_dist * 1.5 * d1.scale_factor < ratio_octave || ratio_dist > ratio_octave * 1.5 * d1.scale_factor) continue;
      map::MapPoint* mp = map_.create_point(*X, kf, d1.frame_id);
      mp->add_observation(kf, static_cast<int>(i));
      mp->add_observation(kf2, best_j);
      kf->add_map_point(mp, static_cast<int>(i));
      kf2->add_map_point(mp, best_j);
      mp->update_descriptor();
      mp->update_normal_and_depth();
      used2[static_cast<std::size_t>(best_j)] = true;
      recent_points_.emplace_back(mp, kf->id());
      ++created;
    }
    if (!options_.lines) continue;
    // Lines not yet in the map (too far for stereo creation): plane intersection with kf2.
    const auto lines1 = kf->map_lines();
    const auto lines2 = kf2->map_lines();
    for (std::size_t a = 0; a < lines1.size(); ++a) {
      if (lines1[a] || kf->map_line(static_cast<int>(a))) continue;
      int best = 60, best_b = -1;
      for (std::size_t b = 0; b < lines2.size(); ++b) {
        if (lines2[b]) continue;
        const int h = features::hamming_distance(d1.line_descriptors.ptr<uint8_t>(static_cast<int>(a)),
                                                 d2.line_descriptors.ptr<uint8_t>(static_cast<int>(b)));
        if (h < best) {
          best = h;
          best_b = static_cast<int>(b);
        }
      }
      if (best_b < 0) continue;
      const auto& s1 = d1.lines[a].segment;
      const auto& s2 = d2.lines[static_cast<std::size_t>(best_b)].segment;
      const auto seg = geometry::triangulate_line(cam, T1, T2, {{s1.start.x, s1.start.y}, {s1.end.x, s1.end.y}},
                                                  {{s2.start.x, s2.start.y}, {s2.end.x, s2.end.y}}, 0.05);
      if (!seg) continue;
      // The two-view segment must agree with the stereo endpoints of view 1 to within 20 %.
      const Eigen::Vector3d s_c = T1 * seg->start, e_c = T1 * seg->end;
      const auto& obs = d1.lines[a];
      if (std::abs(s_c.z() - obs.start_cam.z()) > 0.2 * obs.start_cam.z() ||
          std::abs(e_c.z() - obs.end_cam.z()) > 0.2 * obs.end_cam.z()) {
        continue;
      }
      map::MapLine* ml = map_.create_line(seg->start, seg->end, kf, d1.frame_id);
      ml->add_observation(kf, static_cast<int>(a));
      ml->add_observation(kf2, best_b);
      kf->add_map_line(ml, static_cast<int>(a));
      kf2->add_map_line(ml, best_b);
      ml->update_descriptor();
      ml->update_normal_and_depth();
      recent_lines_.emplace_back(ml, kf->id());
    }
  }
  std::lock_guard lock(stats_mutex_);
  stats_.triangulated_points += created;
}

void LocalMapper::fuse(map::KeyFrame* kf) {
  // Projects the keyframe's map points into its neighbours: where the neighbour's matching
  // keypoint already has a map point, the two are one landmark and the less observed one goes.
  int fused = 0;
  const auto points = kf->map_points();
  for (map::KeyFrame* kf2 : kf->best_covisibles(10)) {
    const geometry::SE3 T2 = kf2->pose();
    const Eigen::Vector3d O2 = kf2->camera_center();
    for (map::MapPoint* mp : points) {
      if (!mp || mp->is_bad() || mp->index_in(kf2) >= 0) continue;
      const int best_j = match_point_in_keyframe(*kf2, T2, O2, *mp);
      if (best_j < 0) continue;
      map::MapPoint* other = kf2->map_point(best_j);
      if (other && !other->is_bad()) {
        if (other == mp) continue;
        if (other->num_observations() > mp->num_observations()) {
          mp->replace_with(other);
        } else {
          other->replace_with(mp);
        }
        ++fused;
      } else {
        mp->add_observation(kf2, best_j);
        kf2->add_map_point(mp, best_j);
      }
    }
  }
  for (map::MapPoint* mp : kf->map_points()) {
    if (mp && !mp->is_bad()) {
      mp->update_descriptor();
      mp->update_normal_and_depth();
    }
  }
  kf->update_connections();
  std::lock_guard lock(stats_mutex_);
  stats_.fused_points += fused;
}

void LocalMapper::local_bundle_adjustment(map::KeyFrame* kf) {
  const auto t0 = Clock::now();
  // Window: the keyframe and its covisibles; points and lines they see; keyframes outside the
  // window that also see those landmarks are fixed.
  std::vector<map::KeyFrame*> local{kf};
  for (auto* n : kf->covisibles()) {
    if (!n->is_bad()) local.push_back(n);
  }
  MapBaProblem window(options_.line_information, options_.far_stereo_baselines, options_.lines);
  for (auto* k : local) window.add_keyframe(k, k->is_origin());
  window.add_landmarks_of(local);
  const auto& problem = window.problem;
  if (problem.point_observations.empty()) return;

  optim::BaOptions ba;
  ba.iterations = options_.ba_iterations;
  ba.second_pass_iterations = options_.ba_second_iterations;
  ba.scale_factor = kf->data().scale_factor;
  ba.linear_solver = optim::BaLinearSolver::kSparseSchur;
  const geometry::StereoCamera cam(kf->data().calib);
  const auto result = optim::local_bundle_adjustment(cam, problem, ba);
  if (!result.usable) {
    spdlog::debug("local BA unusable: {}", result.message);
    return;
  }
  std::lock_guard lock(map_.update_mutex());
  const auto& points = window.points;
  const auto& lines = window.lines;
  for (std::size_t i = 0; i < window.point_observers.size(); ++i) {
    if (!result.point_observation_outlier[i]) continue;
    map::MapPoint* mp = points[static_cast<std::size_t>(problem.point_observations[i].point)];
    map::KeyFrame* k = window.point_observers[i];
    const int idx = mp->index_in(k);
    if (idx >= 0) k->erase_map_point(idx);
    mp->erase_observation(k);
  }
  for (std::size_t i = 0; i < window.line_observers.size(); ++i) {
    if (!result.line_observation_outlier[i]) continue;
    map::MapLine* ml = lines[static_cast<std::size_t>(problem.line_observations[i].line)];
    map::KeyFrame* k = window.line_observers[i];
    const int idx = ml->index_in(k);
    if (idx >= 0) k->erase_map_line(idx);
    ml->erase_observation(k);
  }
  for (std::size_t i = 0; i < window.keyframes.size(); ++i) {
    if (!problem.keyframes[i].fixed) window.keyframes[i]->set_pose(result.poses[i]);
  }
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (points[p]->is_bad()) continue;
    points[p]->set_position(result.points[p]);
    points[p]->update_normal_and_depth();
  }
  for (std::size_t l = 0; l < lines.size(); ++l) {
    if (lines[l]->is_bad()) continue;
    lines[l]->set_endpoints(result.lines[l].start, result.lines[l].end);
    lines[l]->refit_to_observations();
    lines[l]->update_normal_and_depth();
  }
  std::lock_guard stats_lock(stats_mutex_);
  stats_.local_ba_ms.push_back(ms_since(t0));
}

void LocalMapper::cull_keyframes(map::KeyFrame* kf) {
  // A keyframe is redundant when 90 % of its close map points are seen, at the same or a finer
  // scale, by at least three other keyframes (ORB-SLAM2's KeyFrameCulling).
  int culled = 0;
  for (map::KeyFrame* k : kf->covisibles()) {
    if (k->is_origin() || k->is_bad() || !k->loop_edges().empty()) continue;
    const auto& d = k->data();
    const double th_depth = 40.0 * d.calib.baseline;
    const auto pts = k->map_points();
    int total = 0, redundant = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      map::MapPoint* mp = pts[i];
      if (!mp || mp->is_bad()) continue;
      if (d.depth[i] > th_depth || d.depth[i] < 0) continue;
      ++total;
      if (mp->observation_weight() <= 3) continue;
      const int level = d.keypoints[i].octave;
      int seen = 0;
      for (const auto& [other, idx] : mp->observations()) {
        if (other == k || other->is_bad()) continue;
        if (other->data().keypoints[static_cast<std::size_t>(idx)].octave <= level + 1 && ++seen >= 3) break;
      }
      if (seen >= 3) ++redundant;
    }
    if (total > 0 && redundant > options_.culling_redundancy * total) {
      k->set_bad();
      map_.erase_keyframe(k);
      if (database_) database_->erase(k);
      ++culled;
    }
  }
  std::lock_guard lock(stats_mutex_);
  stats_.culled_keyframes += culled;
}

}  // namespace plslam::mapping
