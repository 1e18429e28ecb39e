#include "plslam/features/line_detector.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"

namespace plslam::features {

const char* to_string(LineDetectorKind k) { return k == LineDetectorKind::kLsd ? "lsd" : "grow"; }

LineDetectorKind parse_line_detector(const std::string& name) {
  if (name == "lsd") return LineDetectorKind::kLsd;
  if (name == "grow") return LineDetectorKind::kGrow;
  throw InputError("", "unknown line detector '" + name + "' (expected lsd or grow)");
}

namespace {

// Orders pixel indices by decreasing gradient magnitude with a counting sort (as LSD does):
// exact order does not matter, only that strong pixels seed regions first.
std::vector<int> seeds_by_magnitude(const cv::Mat& mag, float threshold) {
  constexpr int kBins = 1024;
  double max_mag = 0;
  cv::minMaxLoc(mag, nullptr, &max_mag);
  std::vector<int> seeds;
  if (max_mag <= threshold) return seeds;
  const float to_bin = static_cast<float>((kBins - 1) / (max_mag - threshold));
  std::vector<int> count(kBins + 1, 0);
  std::vector<std::pair<int, int>> cand;  // (bin, index)
  cand.reserve(mag.total() / 8);
  for (int y = 1; y < mag.rows - 1; ++y) {
    const float* m = mag.ptr<float>(y);
    for (int x = 1; x < mag.cols - 1; ++x) {
      if (m[x] < threshold) continue;
      const int b = kBins - 1 - static_cast<int>((m[x] - threshold) * to_bin);
      cand.emplace_back(b, y * mag.cols + x);
      ++count[b + 1];
    }
  }
  for (int b = 0; b < kBins; ++b) count[b + 1] += count[b];
  seeds.resize(cand.size());
  for (const auto& [b, idx] : cand) seeds[count[b]++] = idx;
  return seeds;
}

struct RegionFit {
  double mx = 0, my = 0, ex = 1, ey = 0;  // centroid and unit direction (bright side right)
  double tmin = 0, tmax = 0, wmin = 0, wmax = 0;  // extents along / across the direction
};

// Magnitude-weighted centroid and inertia give the line through the region's edge ridge.
RegionFit fit_region(const std::vector<int>& region, const float* mag, int W, float cx, float cy) {
  RegionFit f;
  double sw = 0;
  for (const int p : region) {
    const double w = mag[p];
    sw += w;
    f.mx += w * (p % W);
    f.my += w * (p / W);
  }
  f.mx /= sw;
  f.my /= sw;
  double cxx = 0, cxy = 0, cyy = 0;
  for (const int p : region) {
    const double w = mag[p], dx = p % W - f.mx, dy = p / W - f.my;
    cxx += w * dx * dx;
    cxy += w * dx * dy;
    cyy += w * dy * dy;
  }
  const double theta = 0.5 * std::atan2(2 * cxy, cxx - cyy);  // major axis
  f.ex = std::cos(theta);
  f.ey = std::sin(theta);
  // With y down, the right of e is (-ey, ex); c . (-ey, ex) = cross(e, c) must be positive.
  if (f.ex * cy - f.ey * cx < 0) {
    f.ex = -f.ex;
    f.ey = -f.ey;
  }
  f.tmin = f.wmin = 1e9;
  f.tmax = f.wmax = -1e9;
  for (const int p : region) {
    const double dx = p % W - f.mx, dy = p / W - f.my;
    const double t = dx * f.ex + dy * f.ey, w = -dx * f.ey + dy * f.ex;
    f.tmin = std::min(f.tmin, t);
    f.tmax = std::max(f.tmax, t);
    f.wmin = std::min(f.wmin, w);
    f.wmax = std::max(f.wmax, w);
  }
  return f;
}

}  // namespace

std::vector<LineSegment> grow_line_segments(const LineGradient& g, const LineDetectorOptions& o) {
  const int W = g.magnitude.cols, H = g.magnitude.rows;
  std::vector<LineSegment> out;
  if (W < 3 || H < 3) return out;
  const float* mag = g.magnitude.ptr<float>();
  const short* gx = g.gx.ptr<short>();
  const short* gy = g.gy.ptr<short>();
  // 0 free, 1 used or too weak. Border pixels are never grown into.
  std::vector<uint8_t> status(static_cast<std::size_t>(W) * H, 0);
  for (int i = 0; i < W * H; ++i)
    if (mag[i] < o.min_gradient) status[i] = 1;
  for (int x = 0; x < W; ++x) status[x] = status[(H - 1) * W + x] = 1;
  for (int y = 0; y < H; ++y) status[y * W] = status[y * W + W - 1] = 1;

  const float cos_tol = std::cos(o.angle_tolerance_deg * static_cast<float>(CV_PI) / 180.f);
  const double min_len = o.min_length_px * g.scale;
  const int min_pixels = std::max(4, static_cast<int>(min_len));
  const int offsets[8] = {-W - 1, -W, -W + 1, -1, 1, W - 1, W, W + 1};
  std::vector<int> region;
  region.reserve(4096);

  for (const int seed : seeds_by_magnitude(g.magnitude, o.min_gradient)) {
    if (status[seed]) continue;
    region.clear();
    region.push_back(seed);
    status[seed] = 1;
    float sx = gx[seed] / mag[seed], sy = gy[seed] / mag[seed];
    float cx = sx, cy = sy;  // unit mean gradient direction of the region
    for (std::size_t k = 0; k < region.size(); ++k) {
      const int p = region[k];
      // The free neighbours first, as a bit mask, then only those in the offsets' order: most
      // neighbours are taken or weak, and testing each with a branch mispredicted often (the
      // growth was 80 % of line detection). The order, and so the region, is unchanged.
      unsigned free_mask = 0;
      for (int i = 0; i < 8; ++i) free_mask |= static_cast<unsigned>(status[p + offsets[i]] == 0) << i;
      for (; free_mask != 0; free_mask &= free_mask - 1) {
        const int q = p + offsets[std::countr_zero(free_mask)];
        // Angle test without a division: g . c >= cos(tol) |g|.
        if (gx[q] * cx + gy[q] * cy < cos_tol * mag[q]) continue;
        status[q] = 1;
        region.push_back(q);
        const float inv = 1.f / mag[q];
        sx += gx[q] * inv;
        sy += gy[q] * inv;
        const float n = std::sqrt(sx * sx + sy * sy);
        cx = sx / n;
        cy = sy / n;
      }
    }
    if (static_cast<int>(region.size()) < min_pixels) continue;

    // Fit, then trim pixels that leaked sideways into texture and refit: the edge ridge is
    // only a few pixels wide, a leak is not (LSD shrinks such regions for the same reason).
    RegionFit fit = fit_region(region, mag, W, cx, cy);
    if (fit.wmax - fit.wmin > 2 * o.max_half_width) {
      std::size_t k = 0;
      for (const int p : region) {
        const double dx = p % W - fit.mx, dy = p / W - fit.my;
        if (std::fabs(-dx * fit.ey + dy * fit.ex) <= o.max_half_width) region[k++] = p;
      }
      region.resize(k);
      if (static_cast<int>(region.size()) < min_pixels) continue;
      fit = fit_region(region, mag, W, cx, cy);
    }
    const double len = fit.tmax - fit.tmin;
    if (len < min_len) continue;
    const double density = region.size() / ((len + 1.0) * (fit.wmax - fit.wmin + 1.0));
    if (density < o.min_density) continue;
    const double mx = fit.mx, my = fit.my, ex = fit.ex, ey = fit.ey, tmin = fit.tmin, tmax = fit.tmax;
    LineSegment s;
    s.start = g.to_full(cv::Point2f(static_cast<float>(mx + tmin * ex), static_cast<float>(my + tmin * ey)));
    s.end = g.to_full(cv::Point2f(static_cast<float>(mx + tmax * ex), static_cast<float>(my + tmax * ey)));
    s.response = s.length();
    out.push_back(s);
  }
  return out;
}

void orient_by_gradient(std::vector<LineSegment>& segments, const LineGradient& g) {
  const int W = g.gx.cols, H = g.gx.rows;
  for (auto& s : segments) {
    const cv::Point2f a = g.to_working(s.start), b = g.to_working(s.end);
    const cv::Point2f d = b - a;
    const int n = std::max(2, static_cast<int>(cv::norm(d)));
    double sum = 0;  // sum of cross(d, gradient): positive when the gradient points right
    for (int i = 0; i <= n; ++i) {
      const cv::Point2f p = a + d * (static_cast<float>(i) / n);
      const int x = cvRound(p.x), y = cvRound(p.y);
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      sum += d.x * g.gy.at<short>(y, x) - d.y * g.gx.at<short>(y, x);
    }
    // In image coordinates (y down) the right of d = (dx, dy) is (-dy, dx).
    if (sum < 0) std::swap(s.start, s.end);
  }
}

DetectedLines detect_lines(const cv::Mat& grey, const LineDetectorOptions& o) {
  DetectedLines r;
  r.gradient = compute_line_gradient(grey, o.scale);
  if (o.kind == LineDetectorKind::kGrow) {
    r.segments = grow_line_segments(r.gradient, o);
    return r;
  }
  cv::Mat work = grey;
  if (r.gradient.scale < 1.0) cv::resize(grey, work, r.gradient.magnitude.size(), 0, 0, cv::INTER_AREA);
  auto lsd = cv::createLineSegmentDetector(o.lsd_refine, o.lsd_internal_scale);
  std::vector<cv::Vec4f> raw;
  lsd->detect(work, raw);
  r.segments.reserve(raw.size());
  for (const auto& v : raw) {
    LineSegment s;
    s.start = r.gradient.to_full({v[0], v[1]});
    s.end = r.gradient.to_full({v[2], v[3]});
    s.response = s.length();
    if (s.length() >= o.min_length_px) r.segments.push_back(s);
  }
  orient_by_gradient(r.segments, r.gradient);
  return r;
}

}  // namespace plslam::features
