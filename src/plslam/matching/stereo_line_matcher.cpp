#include "plslam/features/orb_descriptor.h"
#include "plslam/matching/stereo_line_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>

namespace plslam::matching {

using features::LineSegment;

Eigen::Vector3d line_coefficients(const cv::Point2f& s, const cv::Point2f& e) {
  const Eigen::Vector3d ps(s.x, s.y, 1.0), pe(e.x, e.y, 1.0);
  return ps.cross(pe) / (ps.norm() * pe.norm());
}

double column_at_row(const LineSegment& s, double y) {
  const double dy = s.end.y - s.start.y;
  return s.start.x + (y - s.start.y) * (s.end.x - s.start.x) / dy;
}

StereoLineMatch make_stereo_line_match(int left, int right, int distance, const LineSegment& a, double ds, double de,
                                       const StereoCalibration& calib) {
  auto backproject = [&](const cv::Point2f& p, double disp) {
    const double z = calib.bf() / disp;
    return Eigen::Vector3d((p.x - calib.cx) * z / calib.fx, (p.y - calib.cy) * z / calib.fy, z);
  };
  StereoLineMatch m;
  m.left = left;
  m.right = right;
  m.distance = distance;
  m.disparity_start = ds;
  m.disparity_end = de;
  m.P_start = backproject(a.start, ds);
  m.P_end = backproject(a.end, de);
  m.coefficients = line_coefficients(a.start, a.end);
  return m;
}

namespace {

struct Candidate {
  int left, right, distance;
  double d_start, d_end;
};

}  // namespace

std::vector<StereoLineMatch> match_stereo_lines(const features::LineFeatures& L, const features::LineFeatures& R,
                                                const StereoCalibration& calib, const StereoLineMatchOptions& o) {
  if (calib.fx <= 0 || calib.fy <= 0 || calib.baseline <= 0)
    throw std::invalid_argument("match_stereo_lines: calibration needs positive fx, fy and baseline");
  if (L.descriptors.rows != static_cast<int>(L.lines.size()) || R.descriptors.rows != static_cast<int>(R.lines.size()))
    throw std::invalid_argument("match_stereo_lines: descriptors do not match lines");
  const double max_disp = calib.bf() / o.min_depth_m;
  const double min_sin = std::sin(o.min_angle_from_horizontal_deg * CV_PI / 180.0);
  const double min_cos_diff = std::cos(o.max_angle_difference_deg * CV_PI / 180.0);
  const int nl = static_cast<int>(L.lines.size()), nr = static_cast<int>(R.lines.size());

  // Right-line directions, once.
  std::vector<cv::Point2f> rdir(nr);
  for (int j = 0; j < nr; ++j) rdir[j] = R.lines[j].direction();

  std::vector<Candidate> cand;
  std::vector<int> best_l(nl, INT_MAX), second_l(nl, INT_MAX), best_r(nr, INT_MAX);
  for (int i = 0; i < nl; ++i) {
    const LineSegment& a = L.lines[i];
    const cv::Point2f da = a.direction();
    if (std::fabs(da.y) < min_sin) continue;  // near-horizontal: disparity ill-conditioned
    const double ay0 = std::min(a.start.y, a.end.y), ay1 = std::max(a.start.y, a.end.y);
    for (int j = 0; j < nr; ++j) {
      if (da.dot(rdir[j]) < min_cos_diff) continue;
      const LineSegment& b = R.lines[j];
      const double by0 = std::min(b.start.y, b.end.y), by1 = std::max(b.start.y, b.end.y);
      const double overlap = std::min(ay1, by1) - std::max(ay0, by0);
      if (overlap < o.min_row_overlap * std::min(ay1 - ay0, by1 - by0)) continue;
      const double ds = a.start.x - column_at_row(b, a.start.y);
      const double de = a.end.x - column_at_row(b, a.end.y);
      if (!(ds > 0 && de > 0 && ds <= max_disp && de <= max_disp)) continue;
      const int dist = features::hamming_distance(L.descriptors.ptr<uint8_t>(i), R.descriptors.ptr<uint8_t>(j));
      if (dist < best_l[i]) {
        second_l[i] = best_l[i];
        best_l[i] = dist;
      } else if (dist < second_l[i]) {
        second_l[i] = dist;
      }
      best_r[j] = std::min(best_r[j], dist);
      cand.push_back({i, j, dist, ds, de});
    }
  }

  std::vector<StereoLineMatch> out;
  std::vector<bool> taken_left(nl, false), taken_right(nr, false);
  for (const Candidate& c : cand) {
    if (c.distance != best_l[c.left] || c.distance > o.max_hamming || taken_left[c.left] || taken_right[c.right])
      continue;
    if (second_l[c.left] != INT_MAX && c.distance >= o.ratio * second_l[c.left]) continue;
    if (o.cross_check && c.distance != best_r[c.right]) continue;
    taken_left[c.left] = true;
    taken_right[c.right] = true;
    out.push_back(make_stereo_line_match(c.left, c.right, c.distance, L.lines[c.left], c.d_start, c.d_end, calib));
  }
  return out;
}

}  // namespace plslam::matching
