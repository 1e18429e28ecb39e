#include "plslam/map/line_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "plslam/map/descriptor_utils.h"

namespace plslam::map {

std::optional<ProjectedSegment> project_line(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                             const MapLine& line) {
  const Eigen::Vector3d s = T_cw * line.start(), e = T_cw * line.end();
  if (s.z() <= 0.05 || e.z() <= 0.05) return std::nullopt;
  const ProjectedSegment p{cam.project(s), cam.project(e)};
  if (!cam.in_image(p.start) && !cam.in_image(p.end)) return std::nullopt;
  if ((p.end - p.start).norm() < 10) return std::nullopt;
  return p;
}

int best_line_match(const FrameData& d, const ProjectedSegment& p, const cv::Mat& desc, const LineMatchGate& gate,
                    const std::function<bool(std::size_t)>& skip, int* distance) {
  const Eigen::Vector2d dir = p.end - p.start;
  const double len = dir.norm();
  const Eigen::Vector2d u = dir / len;
  const double cos_max_angle = std::cos(gate.max_angle_deg * M_PI / 180.0);
  int best = std::numeric_limits<int>::max(), best_j = -1;
  for (std::size_t j = 0; j < d.lines.size(); ++j) {
    if (skip && skip(j)) continue;
    const auto& seg = d.lines[j].segment;
    const Eigen::Vector2d a(seg.start.x, seg.start.y), b(seg.end.x, seg.end.y);
    const Eigen::Vector2d v = b - a;
    const double vlen = v.norm();
    if (vlen < 1e-6 || std::abs(u.dot(v / vlen)) < cos_max_angle) continue;
    const Eigen::Vector3d& l = d.lines[j].left_line;
    if (std::abs(l.x() * p.start.x() + l.y() * p.start.y() + l.z()) > gate.radius ||
        std::abs(l.x() * p.end.x() + l.y() * p.end.y() + l.z()) > gate.radius) {
      continue;
    }
    // Overlap of the candidate with the projected segment, along the projected direction.
    const double ta = u.dot(a - p.start), tb = u.dot(b - p.start);
    const double overlap = std::min(std::max(ta, tb), len) - std::max(std::min(ta, tb), 0.0);
    if (overlap < gate.min_overlap * len) continue;
    const int h = descriptor_distance(desc, d.line_descriptors.row(static_cast<int>(j)));
    if (h < best) {
      best = h;
      best_j = static_cast<int>(j);
    }
  }
  if (distance) *distance = best;
  return best_j;
}

}  // namespace plslam::map
