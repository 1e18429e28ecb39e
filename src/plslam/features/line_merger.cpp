#include "plslam/features/line_merger.h"

#include <algorithm>
#include <cmath>

namespace plslam::features {

MergeFrame MergeFrame::of(cv::Size s) {
  MergeFrame f;
  f.centre = cv::Point2f(0.5f * (s.width - 1), 0.5f * (s.height - 1));
  f.half_diagonal = 0.5 * std::hypot(s.width, s.height);
  return f;
}

bool can_merge(const LineSegment& a, const LineSegment& b, const MergeFrame& f, const LineMergeOptions& o) {
  // Cheapest tests first: this runs for every pair in the angle window.
  const cv::Point2d da = a.end - a.start, db = b.end - b.start;
  // sqrt rather than std::hypot: hypot's extra care costs more than the whole test here.
  const double la = std::sqrt(da.x * da.x + da.y * da.y), lb = std::sqrt(db.x * db.x + db.y * db.y);
  if (la <= 0 || lb <= 0) return false;
  const double cos_ab = (da.x * db.x + da.y * db.y) / (la * lb);
  if (o.same_polarity && cos_ab <= 0) return false;
  // |dtheta| < tol  <=>  |sin dtheta| < sin tol (for angles below 90 degrees).
  const double sin_ab = std::fabs(da.x * db.y - da.y * db.x) / (la * lb);
  if (sin_ab >= std::sin(o.max_theta_deg * CV_PI / 180.0)) return false;

  if (distance_to_line(a, b.start) > o.max_endpoint_distance_px ||
      distance_to_line(a, b.end) > o.max_endpoint_distance_px)
    return false;

  // Interval of b along a's direction, a occupying [0, la].
  const cv::Point2d ua = da / la;
  double t1 = ua.dot(cv::Point2d(b.start - a.start)), t2 = ua.dot(cv::Point2d(b.end - a.start));
  if (t1 > t2) std::swap(t1, t2);
  const double gap = std::max(t1 - la, -t2);  // positive when disjoint
  if (gap > o.max_gap_px) return false;
  const double overlap = std::min(la, t2) - std::max(0.0, t1);
  if (overlap > o.max_overlap_px) return false;

  const HoughLine ha = to_hough(a, f.centre), hb = to_hough(b, f.centre);
  if (hough_angle_difference(ha.theta, hb.theta) >= o.max_theta_deg * CV_PI / 180.0) return false;
  // Across the theta wrap at pi the same line has the opposite rho.
  const double rho_b = std::fabs(ha.theta - hb.theta) > CV_PI / 2 ? -hb.rho : hb.rho;
  return std::fabs(ha.rho - rho_b) < o.max_rho_fraction * f.half_diagonal;
}

LineSegment fuse_segments(const LineSegment& a, const LineSegment& b) {
  const cv::Point2d pts[4] = {a.start, a.end, b.start, b.end};
  const double wa = std::max(1e-6f, a.length()), wb = std::max(1e-6f, b.length());
  const double w[4] = {wa, wa, wb, wb};
  double sw = 0, mx = 0, my = 0;
  for (int i = 0; i < 4; ++i) {
    sw += w[i];
    mx += w[i] * pts[i].x;
    my += w[i] * pts[i].y;
  }
  mx /= sw;
  my /= sw;
  double cxx = 0, cxy = 0, cyy = 0;
  for (int i = 0; i < 4; ++i) {
    const double dx = pts[i].x - mx, dy = pts[i].y - my;
    cxx += w[i] * dx * dx;
    cxy += w[i] * dx * dy;
    cyy += w[i] * dy * dy;
  }
  const double th = 0.5 * std::atan2(2 * cxy, cxx - cyy);
  cv::Point2d d(std::cos(th), std::sin(th));
  if (d.dot(cv::Point2d(a.end - a.start)) < 0) d = -d;
  double tmin = 1e300, tmax = -1e300;
  for (const auto& p : pts) {
    const double t = d.dot(p - cv::Point2d(mx, my));
    tmin = std::min(tmin, t);
    tmax = std::max(tmax, t);
  }
  LineSegment s;
  s.start = cv::Point2f(static_cast<float>(mx + tmin * d.x), static_cast<float>(my + tmin * d.y));
  s.end = cv::Point2f(static_cast<float>(mx + tmax * d.x), static_cast<float>(my + tmax * d.y));
  s.response = s.length();
  s.fragments = a.fragments + b.fragments;
  return s;
}

std::vector<LineSegment> merge_segments(std::vector<LineSegment> segs, cv::Size image_size,
                                        const LineMergeOptions& o) {
  const MergeFrame frame = MergeFrame::of(image_size);
  const double max_dtheta = o.max_theta_deg * CV_PI / 180.0;
  const double max_drho = o.max_rho_fraction * frame.half_diagonal;
  // Longest first, so each merge uses the most reliable line as the reference.
  std::sort(segs.begin(), segs.end(), [](const auto& a, const auto& b) { return a.length() > b.length(); });
  bool changed = true;
  while (changed) {
    changed = false;
    const std::size_t n = segs.size();
    // Candidates come from a window of the angle-sorted order, so a pass costs n log n plus the
    // few same-angle pairs instead of n^2. The window is twice the gate because a fused
    // segment's angle moves (by less than the gate) within the pass.
    std::vector<double> angle(n), rho(n);
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i) {
      const HoughLine h = to_hough(segs[i], frame.centre);
      angle[i] = h.theta;
      rho[i] = h.rho;
      order[i] = i;
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return angle[a] < angle[b]; });
    std::vector<double> sorted(n);
    for (std::size_t k = 0; k < n; ++k) sorted[k] = angle[order[k]];
    std::vector<bool> dead(n, false);
    std::vector<std::size_t> cand;
    for (std::size_t i = 0; i < n; ++i) {
      if (dead[i]) continue;
      cand.clear();
      const double lo = angle[i] - 2 * max_dtheta, hi = angle[i] + 2 * max_dtheta;
      auto collect = [&](double a, double b) {  // sorted positions with angle in [a, b]
        for (auto it = std::lower_bound(sorted.begin(), sorted.end(), a); it != sorted.end() && *it <= b; ++it)
          cand.push_back(order[static_cast<std::size_t>(it - sorted.begin())]);
      };
      collect(std::max(0.0, lo), std::min(CV_PI, hi));
      if (lo < 0) collect(lo + CV_PI, CV_PI);  // wrap at theta = 0 / pi
      if (hi > CV_PI) collect(0.0, hi - CV_PI);
      for (const std::size_t j : cand) {
        if (j == i || dead[j]) continue;
        // Same rho prefilter (with the sign flip across the wrap), again with a margin of 2.
        const double rho_j = std::fabs(angle[i] - angle[j]) > CV_PI / 2 ? -rho[j] : rho[j];
        if (std::fabs(rho[i] - rho_j) > 2 * max_drho) continue;
        const bool i_longer = segs[i].length() >= segs[j].length();
        const LineSegment& a = i_longer ? segs[i] : segs[j];
        const LineSegment& b = i_longer ? segs[j] : segs[i];
        if (!can_merge(a, b, frame, o)) continue;
        segs[i] = fuse_segments(a, b);
        dead[j] = true;
        changed = true;
      }
    }
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (!dead[i]) segs[k++] = segs[i];
    segs.resize(k);
  }
  for (auto& s : segs) s.response = s.length();
  return segs;
}

void keep_best(std::vector<LineSegment>& segs, std::size_t n) {
  std::sort(segs.begin(), segs.end(), [](const auto& a, const auto& b) { return a.response > b.response; });
  if (segs.size() > n) segs.resize(n);
}

}  // namespace plslam::features
