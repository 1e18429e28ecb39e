#include "plslam/mapping/keyframe_projection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "plslam/features/orb_descriptor.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/map/line_projection.h"

namespace plslam::mapping {

int match_point_in_keyframe(const map::KeyFrame& kf, const geometry::SE3& T_cw, const Eigen::Vector3d& O,
                            const map::MapPoint& mp, const ProjectionMatchOptions& o) {
  const auto& d = kf.data();
  const geometry::StereoCamera cam(d.calib);
  const Eigen::Vector3d P = mp.position();
  const Eigen::Vector3d Xc = T_cw * P;
  if (Xc.z() <= 0) return -1;
  const Eigen::Vector2d uv = cam.project(Xc);
  if (!cam.in_image(uv)) return -1;
  const double dist = (P - O).norm();
  if (dist < mp.min_distance() || dist > mp.max_distance()) return -1;
  const int level = mp.predict_level(dist, d.levels, d.scale_factor);
  const double r = o.point_radius * d.level_scale(level);
  std::array<uint8_t, 32> desc;
  if (!mp.copy_descriptor(desc)) return -1;
  int best = o.point_max_hamming, best_j = -1;
  for (int j : d.points_in_area(uv.x(), uv.y(), r, std::max(0, level - 1), level + 1)) {
    const auto& kp = d.keypoints[static_cast<std::size_t>(j)];
    const double e2 = (uv - Eigen::Vector2d(kp.pt.x, kp.pt.y)).squaredNorm();
    if (e2 > o.point_chi2 * d.level_sigma2(kp.octave)) continue;
    const int h = features::hamming_distance(desc.data(), d.descriptors.ptr<uint8_t>(j));
    if (h < best) {
      best = h;
      best_j = j;
    }
  }
  return best_j;
}

int match_line_in_keyframe(const map::KeyFrame& kf, const geometry::SE3& T_cw, const map::MapLine& ml,
                           const ProjectionMatchOptions& o) {
  const auto& d = kf.data();
  if (d.lines.empty()) return -1;
  const auto projected = map::project_line(geometry::StereoCamera(d.calib), T_cw, ml);
  if (!projected) return -1;
  const cv::Mat desc = ml.descriptor();
  if (desc.empty()) return -1;
  int best = 0;
  const int j = map::best_line_match(d, *projected, desc, {o.line_radius, o.line_max_angle_deg, o.line_min_overlap},
                                     nullptr, &best);
  return j >= 0 && best <= o.line_max_hamming ? j : -1;
}

}  // namespace plslam::mapping
