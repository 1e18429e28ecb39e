#pragma once
// Synthetic stereo scene with exact line ground truth, for the line front-end tests: planar
// quads (fronto-parallel and oblique, rotated in plane) in front of a textured background
// plane, optionally crossed by thin near poles that break the quads' edges into fragments.
// Everything is drawn with anti-aliased sub-pixel polygons from the exact projections of the
// 3D corners, so the projected 3D edges are the ground-truth segments.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/core/types.h"
#include "plslam/features/line_segment.h"

namespace plslam::test {

struct GtEdge {
  cv::Point2f a, b;   // left-image projection
  Eigen::Vector3d n;  // plane normal (left camera frame) of the surface the edge bounds
  double plane_d = 0; // plane: n . X = plane_d
  bool pole = false;
};

struct SyntheticLineScene {
  StereoCalibration calib;
  cv::Mat left, right;
  std::vector<GtEdge> edges;

  // Depth of the plane of edge e seen through left pixel p.
  double depth_at(const GtEdge& e, const cv::Point2f& p) const {
    const Eigen::Vector3d ray((p.x - calib.cx) / calib.fx, (p.y - calib.cy) / calib.fy, 1.0);
    return e.plane_d / e.n.dot(ray);
  }
};

namespace synth_detail {

struct Quad {
  Eigen::Vector3d c;  // centre, metres
  double alpha_deg, beta_deg, half_w, half_h;
  int intensity;
};

inline std::array<Eigen::Vector3d, 4> corners(const Quad& q) {
  const double a = q.alpha_deg * CV_PI / 180, b = q.beta_deg * CV_PI / 180;
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d u = Ry * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
  const Eigen::Vector3d v = Ry * Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
  return {q.c - q.half_w * u - q.half_h * v, q.c + q.half_w * u - q.half_h * v,
          q.c + q.half_w * u + q.half_h * v, q.c - q.half_w * u + q.half_h * v};
}

inline cv::Point2f project(const StereoCalibration& k, const Eigen::Vector3d& X, double shift_x) {
  return {static_cast<float>(k.fx * X.x() / X.z() + k.cx - shift_x),
          static_cast<float>(k.fy * X.y() / X.z() + k.cy)};
}

inline void fill(cv::Mat& img, const std::vector<cv::Point2f>& poly, int intensity) {
  constexpr int kShift = 4;
  std::vector<cv::Point> p;
  for (const auto& q : poly)
    p.emplace_back(cvRound(q.x * (1 << kShift)), cvRound(q.y * (1 << kShift)));
  cv::fillConvexPoly(img, p, cv::Scalar(intensity), cv::LINE_AA, kShift);
}

}  // namespace synth_detail

// A 752x480 EuRoC-like stereo pair (fx 450, baseline 0.11 m).
inline SyntheticLineScene make_line_scene(bool with_poles, unsigned seed = 7) {
  using namespace synth_detail;
  SyntheticLineScene s;
  s.calib = {752, 480, 450.0, 450.0, 375.5, 239.5, 0.11};
  const cv::Size size(s.calib.width, s.calib.height);
  cv::RNG rng(seed);

  // Background plane at 10 m: smooth low-contrast texture, shifted by its disparity.
  const double z_bg = 10.0, d_bg = s.calib.bf() / z_bg;
  cv::Mat tex(size.height, size.width + 64, CV_32F);
  rng.fill(tex, cv::RNG::NORMAL, 0, 40);
  cv::GaussianBlur(tex, tex, cv::Size(0, 0), 5);
  tex += 110;
  cv::Mat tex8;
  tex.convertTo(tex8, CV_8U);
  s.left = tex8(cv::Rect(0, 0, size.width, size.height)).clone();
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, d_bg, 0, 1, 0);
  cv::warpAffine(tex8, s.right, shift, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);

  // Quads in two rows; pixel centre (x, y) at depth z. Two aligned quads in the second row have
  // collinear top edges 40 px apart: distinct edges that merging must keep apart.
  const struct { double x, y, z, alpha, beta, w_px, h_px; int intensity; } layout[] = {
      {110, 120, 3.0, 15, 0, 150, 90, 200},  {290, 120, 4.0, -20, 25, 140, 100, 45},
      {470, 120, 5.0, 30, 0, 150, 80, 190},  {650, 125, 3.5, -10, -30, 140, 90, 60},
      {115, 350, 4.5, 25, -20, 140, 90, 185}, {300, 350, 6.0, -35, 0, 130, 100, 50},
      {475, 340, 3.0, 0, 0, 110, 80, 210},   {625, 340, 3.0, 0, 0, 110, 80, 210},
  };
  std::vector<Quad> quads;
  for (const auto& l : layout) {
    const Eigen::Vector3d c((l.x - s.calib.cx) * l.z / s.calib.fx, (l.y - s.calib.cy) * l.z / s.calib.fy, l.z);
    quads.push_back({c, l.alpha, l.beta, 0.5 * l.w_px * l.z / s.calib.fx, 0.5 * l.h_px * l.z / s.calib.fy, l.intensity});
  }
  std::sort(quads.begin(), quads.end(), [](const Quad& a, const Quad& b) { return a.c.z() > b.c.z(); });
  for (const Quad& q : quads) {
    const auto X = corners(q);
    std::vector<cv::Point2f> pl, pr;
    for (const auto& c : X) {
      pl.push_back(project(s.calib, c, 0));
      pr.push_back(project(s.calib, c, s.calib.bf() / c.z()));
    }
    fill(s.left, pl, q.intensity);
    fill(s.right, pr, q.intensity);
    const Eigen::Vector3d n = (X[1] - X[0]).cross(X[3] - X[0]).normalized();
    for (int i = 0; i < 4; ++i) s.edges.push_back({pl[i], pl[(i + 1) % 4], n, n.dot(X[0]), false});
  }
  if (with_poles) {
    // Thin near poles (1.5 m) that cross the quads and break their edges.
    const double z = 1.5, d = s.calib.bf() / z;
    for (float x = 45.f; x < 740.f; x += 65.f) {
      const float w = 9;
      const std::vector<cv::Point2f> pl = {{x, -5.f}, {x + w, -5.f}, {x + w, 485.f}, {x, 485.f}};
      std::vector<cv::Point2f> pr = pl;
      for (auto& p : pr) p.x -= static_cast<float>(d);
      fill(s.left, pl, 135);
      fill(s.right, pr, 135);
      const Eigen::Vector3d n(0, 0, 1);
      s.edges.push_back({{x, 0.f}, {x, 479.f}, n, z, true});
      s.edges.push_back({{x + w, 0.f}, {x + w, 479.f}, n, z, true});
    }
  }
  cv::Mat noise(size, CV_16S);
  for (cv::Mat* img : {&s.left, &s.right}) {
    rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
    cv::Mat tmp;
    img->convertTo(tmp, CV_16S);
    tmp += noise;
    tmp.convertTo(*img, CV_8U);
  }
  return s;
}

// Whether segment s lies on GT edge e: both endpoints within `dist` px of e's line, direction
// within `angle_deg` (either way round), and s within e's extent (+- `slack` px).
inline bool on_edge(const features::LineSegment& s, const GtEdge& e, double dist = 2.5, double angle_deg = 3.0,
                    double slack = 6.0) {
  const features::LineSegment g{e.a, e.b};
  if (features::distance_to_line(g, s.start) > dist || features::distance_to_line(g, s.end) > dist) return false;
  const cv::Point2f dg = g.direction(), ds = s.direction();
  if (std::fabs(dg.x * ds.x + dg.y * ds.y) < std::cos(angle_deg * CV_PI / 180)) return false;
  const double L = g.length();
  const double t1 = dg.dot(s.start - e.a), t2 = dg.dot(s.end - e.a);
  return std::min(t1, t2) >= -slack && std::max(t1, t2) <= L + slack;
}

// Fraction of GT edge e covered by the segments lying on it.
inline double coverage(const GtEdge& e, const std::vector<features::LineSegment>& segs) {
  const features::LineSegment g{e.a, e.b};
  const double L = g.length();
  const cv::Point2f dg = g.direction();
  std::vector<std::pair<double, double>> iv;
  for (const auto& s : segs) {
    if (!on_edge(s, e)) continue;
    double t1 = dg.dot(s.start - e.a), t2 = dg.dot(s.end - e.a);
    if (t1 > t2) std::swap(t1, t2);
    iv.emplace_back(std::max(0.0, t1), std::min(L, t2));
  }
  std::sort(iv.begin(), iv.end());
  double covered = 0, reach = 0;
  for (const auto& [a, b] : iv) {
    const double from = std::max(a, reach);
    if (b > from) covered += b - from;
    reach = std::max(reach, b);
  }
  return L > 0 ? covered / L : 0;
}

// A tilted bright bar on a 320x240 pair, the right image holding it `shift` px to the left; `skew`
// shifts the right bar's bottom corners further, so disparity grows linearly down the bar. Its two
// long slanted sides are the stereo lines.
inline std::pair<cv::Mat, cv::Mat> make_bar_pair(float shift, float skew = 0) {
  cv::Mat a(240, 320, CV_8U, cv::Scalar(50)), b(240, 320, CV_8U, cv::Scalar(50));
  auto bar = [](cv::Mat& img, float top, float bottom) {
    std::vector<cv::Point> p;
    for (const cv::Point2f q : {cv::Point2f(120 - top, 30), cv::Point2f(170 - top, 30), cv::Point2f(210 - bottom, 210),
                                cv::Point2f(160 - bottom, 210)})
      p.emplace_back(cvRound(q.x * 16), cvRound(q.y * 16));
    cv::fillConvexPoly(img, p, cv::Scalar(200), cv::LINE_AA, 4);
  };
  bar(a, 0, 0);
  bar(b, shift, shift + skew);
  return {a, b};
}

}  // namespace plslam::test
