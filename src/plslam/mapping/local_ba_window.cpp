#include "plslam/mapping/local_ba_window.h"

#include <algorithm>
#include <mutex>
#include <optional>

#include <spdlog/spdlog.h>

#include "plslam/geometry/stereo_camera.h"

namespace plslam::mapping {
namespace {

// The last `n` keyframes of the IMU chain that ends at `kf`, oldest first (empty without a state).
std::vector<map::KeyFrame*> imu_chain_before(map::KeyFrame& kf, int n) {
  std::vector<map::KeyFrame*> chain;
  for (map::KeyFrame* k = &kf; k && static_cast<int>(chain.size()) < n;) {
    const auto imu = k->imu();
    if (!imu) break;
    chain.push_back(k);
    k = imu->previous;
  }
  std::reverse(chain.begin(), chain.end());
  return chain;
}

}  // namespace

MapBaProblem local_ba_window(map::KeyFrame& kf, const LocalBaOptions& o,
                             const std::vector<map::KeyFrame*>& also_free) {
  std::vector<map::KeyFrame*> local{&kf};
  for (auto* n : kf.covisibles()) {
    if (!n->is_bad()) local.push_back(n);
  }
  for (auto* k : also_free) {
    if (k != &kf && !k->is_bad() && std::find(local.begin(), local.end(), k) == local.end()) local.push_back(k);
  }
  const std::vector<map::KeyFrame*> chain = o.imu_window > 0 ? imu_chain_before(kf, o.imu_window) : std::vector<map::KeyFrame*>{};
  for (auto* k : chain) {
    if (std::find(local.begin(), local.end(), k) == local.end()) local.push_back(k);
  }
  MapBaProblem window(o.line_information, o.far_stereo_baselines, o.lines);
  for (auto* k : local) window.add_keyframe(k, k->is_origin());
  window.add_landmarks_of(local);
  if (!chain.empty()) {
    // A free keyframe that shares no landmark with the keyframe before it in time keeps its IMU
    // factor to it even out of the chain: mapped from the IMU's pose after a black-out, it is
    // tied to the map before the gap by that factor alone. Without it, once the chain had moved
    // on, the part after the gap drifted as a free island (a drone's render: 42 mm in 4 s).
    std::vector<map::KeyFrame*> linked = chain;
    for (auto* k : local) {
      const auto imu = k->imu();
      if (imu && imu->previous && k->weight(imu->previous) == 0 && std::find(chain.begin(), chain.end(), k) == chain.end()) {
        linked.push_back(k);
      }
    }
    window.add_imu_factors(linked, o.T_imu_cam, o.reintegration, /*add_missing=*/true);
  }
  return window;
}

void write_back_local_ba(const MapBaProblem& window, const optim::BaResult& result) {
  const auto& problem = window.problem;
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
  window.write_back_imu_states(result);
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
}

optim::BaResult solve_local_ba(const MapBaProblem& window, const map::KeyFrame& kf, const LocalBaOptions& o,
                               const std::atomic<bool>* abort) {
  optim::BaOptions ba;
  ba.iterations = o.iterations;
  ba.second_pass_iterations = o.second_iterations;
  ba.scale_factor = kf.data().scale_factor;
  ba.linear_solver = optim::BaLinearSolver::kSparseSchur;
  ba.abort = abort;
  const geometry::StereoCamera cam(kf.data().calib);
  return optim::local_bundle_adjustment(cam, window.problem, ba);
}

bool apply_local_ba(map::Map& map, const MapBaProblem& window, const optim::BaResult& result) {
  if (!result.usable) {
    spdlog::debug("local BA unusable: {}", result.message);
    return false;
  }
  std::lock_guard lock(map.update_mutex());
  write_back_local_ba(window, result);
  map.note_change();  // poses and positions moved: readers of snapshots redraw
  return true;
}

bool run_local_ba(map::Map& map, map::KeyFrame& kf, const LocalBaOptions& o, const std::atomic<bool>* abort,
                  bool* aborted) {
  const MapBaProblem window = local_ba_window(kf, o);
  if (window.problem.point_observations.empty()) return false;
  const auto result = solve_local_ba(window, kf, o, abort);
  if (aborted) *aborted = result.aborted;
  return apply_local_ba(map, window, result);
}

}  // namespace plslam::mapping
