#include "plslam/map/map_line.h"

#include <algorithm>
#include <limits>

#include <Eigen/Eigenvalues>

#include "plslam/map/keyframe.h"
#include "plslam/map/landmark_impl.h"

namespace plslam::map {

template class Landmark<MapLine>;

MapLine::MapLine(long id, const Eigen::Vector3d& start, const Eigen::Vector3d& end, KeyFrame* reference,
                 long created_frame)
    : Landmark(id, reference, created_frame), start_(start), end_(end) {}

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

MapLine* MapLine::slot(const KeyFrame& kf, int index) { return kf.map_line(index); }

void MapLine::set_slot(KeyFrame& kf, int index, MapLine* value) {
  if (value) {
    kf.add_map_line(value, index);
  } else {
    kf.erase_map_line(index);
  }
}

cv::Mat MapLine::descriptor_row(const KeyFrame& kf, int index) { return kf.data().line_descriptors.row(index); }

bool MapLine::is_stereo(const KeyFrame& kf, int index) {
  return kf.data().lines.at(static_cast<std::size_t>(index)).stereo;
}

void MapLine::update_normal_and_depth() {
  const auto obs = observation_list();
  KeyFrame* ref = reference();
  const Eigen::Vector3d m = midpoint();
  if (obs.empty() || !ref) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, idx] : obs) normal += (m - kf->camera_center()).normalized();
  const double dist = (m - ref->camera_center()).norm();
  set_normal_and_range(normal.normalized(), 0.5 * dist, 2.0 * dist);
}

bool MapLine::refit_to_observations() {
  const Eigen::Vector3d a = start(), b = end();
  const Eigen::Vector3d mid = 0.5 * (a + b);
  const auto obs = observation_list();
  // 1. Direction: normal to every observed plane.
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
  for (const auto& [kf, idx] : obs) {
    if (kf->is_bad()) continue;
    const auto& data = kf->data();
    const auto& o = data.lines.at(static_cast<std::size_t>(idx));
    const Eigen::Matrix3d R_wc = kf->pose_inverse().rotation();
    for (const Eigen::Vector3d* l : {&o.left_line, &o.right_line}) {
      if (l == &o.right_line && !o.stereo) continue;
      // The plane of image line l through the camera: normal K' l (same for the right camera,
      // whose plane is only shifted by the baseline).
      const Eigen::Vector3d n = R_wc * Eigen::Vector3d(data.calib.fx * l->x(), data.calib.fy * l->y(),
                                                       data.calib.cx * l->x() + data.calib.cy * l->y() + l->z());
      if (n.norm() > 0) N += n.normalized() * n.normalized().transpose();
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(N);
  Eigen::Vector3d d = b - a;
  const double len = d.norm();
  // Fixed by the planes when two of them differ by more than a few degrees: the second smallest
  // eigenvalue is then clearly above zero.
  constexpr double kMinSpread = 0.01;
  if (eig.info() == Eigen::Success && eig.eigenvalues()(1) > kMinSpread) {
    const Eigen::Vector3d e = eig.eigenvectors().col(0);
    d = len > 1e-9 && e.dot(d) < 0 ? Eigen::Vector3d(-e) : e;
  } else if (len > 1e-9) {
    d /= len;
  } else {
    return false;
  }
  // 2. Extent: where the observed endpoints' rays meet the line.
  constexpr double kMinSin2 = 0.0076;  // sin^2(5 degrees)
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
  for (const auto& [kf, idx] : obs) {
    if (kf->is_bad()) continue;
    const auto& data = kf->data();
    const auto& seg = data.lines.at(static_cast<std::size_t>(idx)).segment;
    const geometry::SE3 T_wc = kf->pose_inverse();
    const Eigen::Vector3d w = mid - T_wc.translation();
    for (const cv::Point2f& px : {seg.start, seg.end}) {
      const Eigen::Vector3d r = T_wc.rotation() * Eigen::Vector3d((px.x - data.calib.cx) / data.calib.fx,
                                                                   (px.y - data.calib.cy) / data.calib.fy, 1.0);
      // Closest point of the line mid + t d to the ray C + s r.
      const double rr = r.squaredNorm(), dr = d.dot(r);
      const double denom = rr - dr * dr;
      if (denom < kMinSin2 * rr) continue;
      const double t = (dr * r.dot(w) - rr * d.dot(w)) / denom;
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
    }
  }
  if (!(t_max > t_min)) return false;
  set_endpoints(mid + t_min * d, mid + t_max * d);
  return true;
}

}  // namespace plslam::map
