#include "plslam/eval/kitti_metric.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <Eigen/LU>
#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::eval {
namespace {

constexpr std::array<double, 8> kLengths = {100, 200, 300, 400, 500, 600, 700, 800};
constexpr std::size_t kStepFrames = 10;

// The devkit's rotation error: the angle from the trace, clamped into acos' domain.
double devkit_rotation_error(const Eigen::Matrix3d& R) {
  const double d = 0.5 * (R.trace() - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

}  // namespace

KittiMetric kitti_odometry_metric(const Trajectory& gt, const Trajectory& est) {
  if (gt.size() != est.size()) throw std::invalid_argument("kitti_odometry_metric: unpaired trajectories");
  const std::size_t n = gt.size();
  std::vector<double> dist(n, 0.0);  // path length along the ground truth
  for (std::size_t i = 1; i < n; ++i) {
    dist[i] = dist[i - 1] + (gt[i].T.translation() - gt[i - 1].T.translation()).norm();
  }

  KittiMetric m;
  for (std::size_t first = 0; first < n; first += kStepFrames) {
    for (double len : kLengths) {
      // First frame whose path distance exceeds dist[first] + len (dist is non-decreasing).
      const auto it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first), dist.end(),
                                       dist[first] + len);
      if (it == dist.end()) continue;
      const std::size_t last = static_cast<std::size_t>(it - dist.begin());
      // General 4x4 inverses, as the devkit's Matrix::inv: poses read as written from KITTI files
      // are not exactly rigid, and the trace-based angle is sensitive to that.
      const Eigen::Matrix4d delta_gt = gt[first].T.matrix().inverse() * gt[last].T.matrix();
      const Eigen::Matrix4d delta_est = est[first].T.matrix().inverse() * est[last].T.matrix();
      const Eigen::Matrix4d error = delta_est.inverse() * delta_gt;
      m.segments.push_back({first, last, len, error.topRightCorner<3, 1>().norm() / len,
                            devkit_rotation_error(error.topLeftCorner<3, 3>()) / len});
    }
  }
  if (m.segments.empty()) {
    throw InputError("", fmt::format("KITTI metric: the ground truth path ({:.1f} m) is shorter "
                                     "than the shortest segment (100 m)", n ? dist.back() : 0.0));
  }
  double t_sum = 0.0, r_sum = 0.0;
  for (const auto& s : m.segments) {
    t_sum += s.t_err;
    r_sum += s.r_err;
  }
  const double count = static_cast<double>(m.segments.size());
  m.t_rel_percent = 100.0 * t_sum / count;
  m.r_rel_deg_per_100m = 100.0 * (r_sum / count) * 180.0 / M_PI;
  return m;
}

}  // namespace plslam::eval
