#include "plslam/eval/rpe.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::eval {
namespace {

IdPairs pairs_by_index(std::size_t n, std::size_t delta, bool all_pairs) {
  IdPairs pairs;
  if (all_pairs) {
    for (std::size_t i = 0; i + delta < n; ++i) pairs.emplace_back(i, i + delta);
  } else {
    for (std::size_t i = 0; i + delta < n; i += delta) pairs.emplace_back(i, i + delta);
  }
  return pairs;
}

double step_length(const Trajectory& poses, std::size_t i) {
  return (poses[i].T.translation() - poses[i - 1].T.translation()).norm();
}

IdPairs pairs_by_path_consecutive(const Trajectory& poses, double delta) {
  std::vector<std::size_t> ids;
  double path = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) path += step_length(poses, i);
    if (path >= delta) {
      ids.push_back(i);
      path = 0.0;
    }
  }
  IdPairs pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

IdPairs pairs_by_path_all(const Trajectory& poses, double delta, double tol) {
  const std::size_t n = poses.size();
  std::vector<double> dist(n, 0.0);  // accumulated path length from pose 0
  for (std::size_t i = 1; i < n; ++i) dist[i] = dist[i - 1] + step_length(poses, i);
  IdPairs pairs;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    // d(k) = dist[k] - dist[i] is non-decreasing in k, so |d(k) - delta| is unimodal: the nearest
    // is around the first k with d(k) >= delta.
    auto from_i = [&](std::size_t k) { return dist[k] - dist[i]; };
    std::size_t lo = i + 1, hi = n;  // first k in [i+1, n) with d(k) >= delta, or n
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (from_i(mid) >= delta) hi = mid; else lo = mid + 1;
    }
    std::size_t best = std::min(lo, n - 1);
    if (lo > i + 1 && (lo == n || std::abs(from_i(lo - 1) - delta) <= std::abs(from_i(lo) - delta))) {
      best = lo - 1;
    }
    // Like numpy's argmin, take the first index of a run of equal distances (standstill).
    const double value = from_i(best);
    std::size_t a = i + 1, b = best;
    while (a < b) {
      const std::size_t mid = a + (b - a) / 2;
      if (from_i(mid) >= value) b = mid; else a = mid + 1;
    }
    best = a;
    if (std::abs(from_i(best) - delta) > tol) continue;
    pairs.emplace_back(i, best);
  }
  return pairs;
}

}  // namespace

IdPairs rpe_id_pairs(const Trajectory& poses, const RpeOptions& options) {
  if (!(options.delta > 0.0) || !std::isfinite(options.delta)) {
    throw InputError("", fmt::format("RPE delta must be positive, got {}", options.delta));
  }
  IdPairs pairs;
  if (options.unit == DeltaUnit::kFrames) {
    if (options.delta != std::floor(options.delta)) {
      throw InputError("", fmt::format("RPE delta in frames must be an integer, got {}", options.delta));
    }
    pairs = pairs_by_index(poses.size(), static_cast<std::size_t>(options.delta), options.all_pairs);
  } else if (options.all_pairs) {
    pairs = pairs_by_path_all(poses, options.delta, options.delta * options.rel_delta_tol);
  } else {
    pairs = pairs_by_path_consecutive(poses, options.delta);
  }
  if (pairs.empty()) {
    throw InputError("", fmt::format("RPE delta {} {} gives no pose pair on a trajectory of {} poses",
                                     options.delta,
                                     options.unit == DeltaUnit::kFrames ? "frames" : "m",
                                     poses.size()));
  }
  return pairs;
}

double rotation_angle(const Eigen::Matrix3d& R) {
  // sin(angle) from the skew part, cos(angle) from the trace: atan2 keeps full precision near 0
  // and near pi.
  const Eigen::Vector3d axis_sin(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double s = 0.5 * axis_sin.norm();
  const double c = 0.5 * (R.trace() - 1.0);
  return std::atan2(s, c);
}

RpeErrors compute_rpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options) {
  if (gt.size() != est.size()) throw std::invalid_argument("compute_rpe: unpaired trajectories");
  RpeErrors r;
  r.pairs = rpe_id_pairs(est, options);
  r.trans_m.reserve(r.pairs.size());
  r.rot_deg.reserve(r.pairs.size());
  for (const auto& [i, j] : r.pairs) {
    const Eigen::Isometry3d Q_rel = gt[i].T.inverse() * gt[j].T;
    const Eigen::Isometry3d P_rel = est[i].T.inverse() * est[j].T;
    const Eigen::Isometry3d E = Q_rel.inverse() * P_rel;
    r.trans_m.push_back(E.translation().norm());
    r.rot_deg.push_back(rotation_angle(E.linear()) * 180.0 / M_PI);
  }
  return r;
}

}  // namespace plslam::eval
