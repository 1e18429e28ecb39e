#include "plslam/matching/guided_stereo_lines.h"

#include "plslam/features/line_descriptor.h"
#include "plslam/features/line_gradient.h"
#include "plslam/features/orb_descriptor.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <climits>
#include <cstring>
#include <optional>
#include <stdexcept>

namespace plslam::matching {

void GuidedStereoLineOptions::validate() const {
  auto fail = [](const char* what) { throw std::invalid_argument(std::string("guided stereo lines: ") + what); };
  if (max_samples < 3) fail("max_samples must be at least 3");
  if (!(sample_spacing_px > 0)) fail("sample_spacing_px must be positive");
  if (min_edge_step < 1 || min_edge_step > 510) fail("min_edge_step must be in [1, 510]");
  if (!(max_normal_angle_deg > 0 && max_normal_angle_deg < 90)) fail("max_normal_angle_deg must be in (0, 90)");
  if (patch_half_width < 1 || patch_half_height < 0) fail("patch half sizes must be >= 1 (width) and >= 0 (height)");
  if (!(min_zncc > -1 && min_zncc < 1)) fail("min_zncc must be in (-1, 1)");
  if (candidates_per_row < 1) fail("candidates_per_row must be at least 1");
  if (!(inlier_px > 0)) fail("inlier_px must be positive");
  if (!(min_inlier_share > 0 && min_inlier_share <= 1)) fail("min_inlier_share must be in (0, 1]");
  if (min_inliers < 2) fail("min_inliers must be at least 2");
  if (!(max_disparity_slope > 0)) fail("max_disparity_slope must be positive");
  if (!(lbd_inlier_share > 0 && lbd_inlier_share <= min_inlier_share))
    fail("lbd_inlier_share must be in (0, min_inlier_share]");
  if (lbd_candidates < 1) fail("lbd_candidates must be at least 1");
  if (!(lbd_scale > 0 && lbd_scale <= 1)) fail("lbd_scale must be in (0, 1]");
}

RowEdges::RowEdges(const cv::Mat& image, int min_step) {
  if (image.empty() || image.type() != CV_8UC1) throw std::invalid_argument("RowEdges: needs an 8-bit grey image");
  const int W = image.cols, H = image.rows;
  row_start_.assign(static_cast<std::size_t>(H) + 1, 0);
  edges_.reserve(static_cast<std::size_t>(W) * H / 8);
  // Per row: the derivative and its magnitude in plain loops the compiler vectorises, then a
  // scan that skips runs of weak pixels eight at a time.
  std::vector<short> d(static_cast<std::size_t>(W) + 8, 0), a(static_cast<std::size_t>(W) + 8, 0);
  std::vector<uint8_t> strong(static_cast<std::size_t>(W) + 8, 0);
  for (int y = 0; y < H; ++y) {
    row_start_[static_cast<std::size_t>(y)] = static_cast<int>(edges_.size());
    if (y < 1 || y + 1 >= H || W < 5) continue;  // the 3x3 direction needs the rows around
    const uint8_t* r = image.ptr<uint8_t>(y);
    const uint8_t* up = image.ptr<uint8_t>(y - 1);
    const uint8_t* down = image.ptr<uint8_t>(y + 1);
    for (int x = 1; x + 1 < W; ++x) d[x] = static_cast<short>(r[x + 1] - r[x - 1]);
    for (int x = 1; x + 1 < W; ++x) a[x] = static_cast<short>(d[x] < 0 ? -d[x] : d[x]);
    for (int x = 2; x + 2 < W; ++x)  // zero outside [2, W - 3], so the 8-byte blocks below stay in bounds
      // Bitwise on ints, not &&: no branches, so the loop vectorises (and clang does not warn).
      strong[x] = static_cast<uint8_t>(int{a[x] >= min_step} & int{a[x] >= a[x - 1]} & int{a[x] > a[x + 1]});
    for (int x0 = 0; x0 + 2 < W; x0 += 8) {
      uint64_t block;  // one byte per pixel, 0 or 1: each set bit is one edge
      std::memcpy(&block, &strong[static_cast<std::size_t>(x0)], 8);
      for (; block; block &= block - 1) {
        const int x = x0 + (__builtin_ctzll(block) >> 3);
        // 3x3 sums of both derivatives give the edge's direction.
        const int gx = (up[x + 1] - up[x - 1]) + d[x] + (down[x + 1] - down[x - 1]);
        const int gy = (down[x - 1] - up[x - 1]) + (down[x] - up[x]) + (down[x + 1] - up[x + 1]);
        edges_.push_back({x, d[x], static_cast<short>(gx), static_cast<short>(gy)});
      }
    }
  }
  row_start_[static_cast<std::size_t>(H)] = static_cast<int>(edges_.size());
}

std::pair<const RowEdges::Edge*, const RowEdges::Edge*> RowEdges::range(int y, int x0, int x1) const {
  if (y < 0 || y + 1 >= static_cast<int>(row_start_.size()) || x1 < x0) return {nullptr, nullptr};
  const Edge* b = edges_.data() + row_start_[static_cast<std::size_t>(y)];
  const Edge* e = edges_.data() + row_start_[static_cast<std::size_t>(y) + 1];
  auto by_x = [](const Edge& a, int x) { return a.x < x; };
  const Edge* lo = std::lower_bound(b, e, x0, by_x);
  const Edge* hi = std::lower_bound(lo, e, x1 + 1, by_x);
  return {lo, hi};
}

namespace {

struct RowCandidate {
  double d;     // disparity, sub-pixel
  double zncc;  // of the windows around the two integer peaks
};

// Signed row derivative of an 8-bit image; the caller keeps 1 <= x <= cols - 2.
inline int row_step(const cv::Mat& img, int y, int x) {
  const uint8_t* r = img.ptr<uint8_t>(y);
  return r[x + 1] - r[x - 1];
}

// Sub-pixel offset of a peak from f(-1), f(0), f(+1) (parabola through the three), in [-0.5, 0.5].
inline double parabola_peak(double fm, double f0, double fp) {
  const double den = fm - 2 * f0 + fp;
  if (den >= 0) return 0;
  return std::clamp(0.5 * (fm - fp) / den, -0.5, 0.5);
}

// A window of the left image around (x, y), with the sums ZNCC needs.
struct Patch {
  std::vector<uint8_t> v;
  long sum = 0;
  double centred_norm = 0;  // sqrt(sum of (v - mean)^2)
};

Patch left_patch(const cv::Mat& img, int x, int y, int hw, int hh) {
  Patch p;
  p.v.reserve(static_cast<std::size_t>((2 * hw + 1) * (2 * hh + 1)));
  long ss = 0;
  for (int dy = -hh; dy <= hh; ++dy) {
    const uint8_t* r = img.ptr<uint8_t>(y + dy);
    for (int dx = -hw; dx <= hw; ++dx) {
      p.v.push_back(r[x + dx]);
      p.sum += r[x + dx];
      ss += r[x + dx] * r[x + dx];
    }
  }
  const double n = static_cast<double>(p.v.size());
  p.centred_norm = std::sqrt(std::max(0.0, static_cast<double>(ss) - static_cast<double>(p.sum) * p.sum / n));
  return p;
}

// Integer sums (a window of at most a few hundred 8-bit pixels fits in 32 bits).
double zncc(const Patch& l, const cv::Mat& img, int x, int y, int hw, int hh) {
  int s = 0, ss = 0, cross = 0;
  std::size_t k = 0;
  for (int dy = -hh; dy <= hh; ++dy) {
    const uint8_t* r = img.ptr<uint8_t>(y + dy) + x - hw;
    for (int dx = 0; dx <= 2 * hw; ++dx, ++k) {
      const int v = r[dx];
      s += v;
      ss += v * v;
      cross += l.v[k] * v;
    }
  }
  const double n = static_cast<double>(l.v.size());
  const double var = ss - static_cast<double>(s) * s / n;
  if (var <= 1e-9 || l.centred_norm <= 1e-9) return -1;
  return (cross - static_cast<double>(l.sum) * s / n) / (l.centred_norm * std::sqrt(var));
}

// One sampled row of a left segment: the left edge, and the right edges tested so far.
struct Sample {
  int y = 0;
  double xL = 0;  // sub-pixel left edge
  Patch patch;
  std::vector<std::pair<int, RowCandidate>> tested;  // right edge x -> candidate (zncc < -1: refused), by x
};

class RowSearch {
 public:
  RowSearch(const cv::Mat& right, const RowEdges& edges, const GuidedStereoLineOptions& o, int sign, double nx,
            double ny, double max_disp)
      : right_(right), edges_(edges), o_(o), sign_(sign), nx_(nx), ny_(ny), max_disp_(max_disp),
        min_cos2_(std::pow(std::cos(o.max_normal_angle_deg * CV_PI / 180.0), 2)) {}

  // Right candidates of row s with disparity in [d0, d1], each tested once per row.
  template <typename F>
  void for_each(Sample& s, double d0, double d1, F&& f) const {
    const int margin = std::max(o_.patch_half_width, 2) + 1;
    // Clamped in double first: a huge disparity limit must not overflow the conversion.
    const double lo_x = std::clamp(std::floor(s.xL - d1) - 1, -1.0, static_cast<double>(right_.cols));
    const double hi_x = std::clamp(std::ceil(s.xL - d0) + 1, -1.0, static_cast<double>(right_.cols));
    const int x0 = std::max(margin, static_cast<int>(lo_x));
    const int x1 = std::min(right_.cols - 1 - margin, static_cast<int>(hi_x));
    const auto [lo, hi] = edges_.range(s.y, x0, x1);
    for (const auto* e = lo; e != hi; ++e) {
      if ((e->step > 0 ? 1 : -1) != sign_) continue;
      const RowCandidate c = test(s, *e);
      if (c.zncc >= o_.min_zncc && c.d >= d0 && c.d <= d1) f(c);
    }
  }

 private:
  RowCandidate test(Sample& s, const RowEdges::Edge& e) const {
    const auto at = std::lower_bound(s.tested.begin(), s.tested.end(), e.x,
                                     [](const std::pair<int, RowCandidate>& t, int x) { return t.first < x; });
    if (at != s.tested.end() && at->first == e.x) return at->second;
    const auto slot = at - s.tested.begin();
    RowCandidate c{0, -2};
    const int y = s.y;
    // The right edge must face the way the left one does.
    const double gx = e.gx, gy = e.gy, along = gx * nx_ + gy * ny_;
    if (along > 0 && along * along >= min_cos2_ * (gx * gx + gy * gy)) {
      const double z = zncc(s.patch, right_, e.x, y, o_.patch_half_width, o_.patch_half_height);
      const double xR =
          e.x + parabola_peak(sign_ * row_step(right_, y, e.x - 1), sign_ * e.step, sign_ * row_step(right_, y, e.x + 1));
      const double d = s.xL - xR;
      if (z >= o_.min_zncc && d > 0 && d <= max_disp_) c = {d, z};
    }
    s.tested.insert(s.tested.begin() + slot, {e.x, c});
    return c;
  }

  const cv::Mat& right_;
  const RowEdges& edges_;
  const GuidedStereoLineOptions& o_;
  int sign_;
  double nx_, ny_, max_disp_, min_cos2_;
};

struct Fit {
  double alpha = 0, beta = 0;  // d(y) = alpha + beta y
  int inliers = 0;
  double score = 0;  // summed ZNCC of the agreeing candidates
};

// Rows with a candidate within `tol` of d(y) (the closest one counts).
Fit evaluate(std::vector<Sample>& samples, const RowSearch& search, double alpha, double beta, double tol,
             std::vector<RowCandidate>* chosen = nullptr) {
  Fit f{alpha, beta, 0, 0};
  if (chosen) chosen->assign(samples.size(), RowCandidate{0, -2});
  for (std::size_t k = 0; k < samples.size(); ++k) {
    Sample& s = samples[k];
    const double dh = alpha + beta * s.y;
    double best = tol;
    RowCandidate pick{0, -2};
    search.for_each(s, dh - tol, dh + tol, [&](const RowCandidate& c) {
      const double r = std::fabs(c.d - dh);
      if (r < best) {
        best = r;
        pick = c;
      }
    });
    if (pick.zncc < -1) continue;
    ++f.inliers;
    f.score += pick.zncc;
    if (chosen) (*chosen)[k] = pick;
  }
  return f;
}

struct Refined {
  double d_start, d_end;  // endpoint disparities
  int inliers;            // rows that agree with the refitted disparity
};

// Least squares over the rows that agree with f, then the checks on the result (at least `needed`
// rows agree with the refit); or nothing.
std::optional<Refined> refine(std::vector<Sample>& samples, const RowSearch& search, const Fit& f,
                              const features::LineSegment& a, int needed, double max_disp,
                              const GuidedStereoLineOptions& o) {
  std::vector<RowCandidate> chosen;
  evaluate(samples, search, f.alpha, f.beta, o.inlier_px, &chosen);
  double sw = 0, sy = 0, sd = 0, syy = 0, syd = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (chosen[k].zncc < -1) continue;
    const double y = samples[k].y, d = chosen[k].d;
    sw += 1;
    sy += y;
    sd += d;
    syy += y * y;
    syd += y * d;
  }
  if (sw < 2) return std::nullopt;
  const double var = syy - sy * sy / sw;
  const double beta = var > 1e-6 ? (syd - sy * sd / sw) / var : 0.0;
  const double alpha = (sd - beta * sy) / sw;
  const int inliers = evaluate(samples, search, alpha, beta, o.inlier_px).inliers;
  if (inliers < needed) return std::nullopt;
  const double ds = alpha + beta * a.start.y, de = alpha + beta * a.end.y;
  if (!(ds > 0 && de > 0 && ds <= max_disp && de <= max_disp)) return std::nullopt;
  if (std::fabs(de - ds) > o.max_disparity_slope * a.length()) return std::nullopt;
  return Refined{ds, de, inliers};
}

// Most rows explained by a fit whose middle-row disparity differs from `mid` (0 if none).
int second_inliers(const std::vector<Fit>& fits, double mid, double y_mid, double tol) {
  int n = 0;
  for (const Fit& f : fits)
    if (std::fabs(f.alpha + f.beta * y_mid - mid) > 2 * tol) n = std::max(n, f.inliers);
  return n;
}

struct Pending {
  int left;
  std::vector<std::pair<double, double>> options;  // endpoint disparities of each candidate
};

}  // namespace

std::vector<StereoLineMatch> match_stereo_lines_guided(const features::LineFeatures& L, const cv::Mat& left,
                                                       const cv::Mat& right, const StereoCalibration& calib,
                                                       const StereoLineMatchOptions& mo,
                                                       const GuidedStereoLineOptions& o) {
  o.validate();
  if (calib.fx <= 0 || calib.fy <= 0 || calib.baseline <= 0)
    throw std::invalid_argument("match_stereo_lines_guided: calibration needs positive fx, fy and baseline");
  if (left.empty() || right.empty() || left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size())
    throw std::invalid_argument("match_stereo_lines_guided: needs two 8-bit grey images of one size");
  const int W = left.cols, H = left.rows, hw = o.patch_half_width, hh = o.patch_half_height;
  const int margin_x = std::max(hw, 2) + 1, margin_y = std::max(hh, 1);
  const double max_disp = calib.bf() / mo.min_depth_m;
  const double min_sin = std::sin(mo.min_angle_from_horizontal_deg * CV_PI / 180.0);
  const RowEdges edges(right, o.min_edge_step);

  if (L.descriptors.rows != static_cast<int>(L.lines.size()))
    throw std::invalid_argument("match_stereo_lines_guided: descriptors do not match lines");
  std::vector<StereoLineMatch> out;
  std::vector<Pending> pending;
  std::vector<Sample> samples;
  std::vector<RowCandidate> low, high;
  for (int i = 0; i < static_cast<int>(L.lines.size()); ++i) {
    const features::LineSegment& a = L.lines[static_cast<std::size_t>(i)];
    const cv::Point2f da = a.direction();
    if (std::fabs(da.y) < min_sin) continue;  // the row crosses a flat line at a poorly defined column
    const int sign = da.y < 0 ? 1 : -1;        // the bright side is right of start->end
    const RowSearch search(right, edges, o, sign, -da.y, da.x, max_disp);

    const int n = std::clamp(static_cast<int>(a.length() / o.sample_spacing_px), 3, o.max_samples);
    samples.clear();
    int sampled = 0, last_row = -1;
    for (int k = 0; k < n; ++k) {
      const cv::Point2f p = a.start + (a.end - a.start) * static_cast<float>((k + 0.5) / n);
      const int y = cvRound(p.y);
      if (y == last_row || y < margin_y || y >= H - margin_y) continue;
      last_row = y;
      const int xc = cvRound(column_at_row(a, y));
      if (xc < margin_x + 2 || xc >= W - margin_x - 2) continue;
      ++sampled;
      // The left edge, located exactly as the right ones are, so both peaks share any bias.
      int xb = -1, fb = o.min_edge_step - 1;
      for (int x = xc - 2; x <= xc + 2; ++x) {
        const int f = sign * row_step(left, y, x);
        if (f > fb && f >= sign * row_step(left, y, x - 1) && f >= sign * row_step(left, y, x + 1)) {
          fb = f;
          xb = x;
        }
      }
      if (xb < 0) continue;
      Sample s;
      s.y = y;
      s.xL = xb + parabola_peak(sign * row_step(left, y, xb - 1), fb, sign * row_step(left, y, xb + 1));
      s.patch = left_patch(left, xb, y, hw, hh);
      samples.push_back(std::move(s));
    }
    const int needed = std::max(o.min_inliers, static_cast<int>(std::ceil(o.min_inlier_share * sampled)));
    const int relaxed = std::max(o.min_inliers, static_cast<int>(std::ceil(o.lbd_inlier_share * sampled)));
    const std::size_t m = samples.size();
    if (static_cast<int>(m) < relaxed) continue;

    // Only two rows search the whole disparity range, the first and the last that have a
    // candidate (of the two at each end, which survives one occluded or textureless end row).
    // Their candidate pairs are the hypotheses; the other rows are searched only around each.
    auto anchor_candidates = [&](std::size_t k, std::vector<RowCandidate>& c) {
      c.clear();
      search.for_each(samples[k], 0, max_disp, [&](const RowCandidate& x) { c.push_back(x); });
      const auto keep = std::min<std::size_t>(c.size(), static_cast<std::size_t>(o.candidates_per_row));
      std::partial_sort(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(keep), c.end(),
                        [](const RowCandidate& p, const RowCandidate& q) { return p.zncc > q.zncc; });
      c.resize(keep);
    };
    std::size_t lo = 0, hi = m - 1;
    anchor_candidates(lo, low);
    if (low.empty()) anchor_candidates(++lo, low);
    anchor_candidates(hi, high);
    if (high.empty()) anchor_candidates(--hi, high);
    if (low.empty() || high.empty() || hi <= lo) continue;
    std::vector<Fit> fits;
    const Sample &sp = samples[lo], &sq = samples[hi];
    for (const auto& cp : low)
      for (const auto& cq : high) {
        const double beta = (cq.d - cp.d) / (sq.y - sp.y);
        const double alpha = cp.d - beta * sp.y;
        fits.push_back(evaluate(samples, search, alpha, beta, o.inlier_px));
      }
    std::sort(fits.begin(), fits.end(), [](const Fit& p, const Fit& q) {
      return p.inliers != q.inliers ? p.inliers > q.inliers : p.score > q.score;
    });
    // Distinct explanations of the rows: fits whose disparities at the middle row differ.
    const double y_mid = 0.5 * (a.start.y + a.end.y);
    std::vector<std::pair<double, double>> options;  // endpoint disparities
    std::vector<double> mids;
    // Every explanation is refined with the relaxed share. The best one keeps the strict share
    // through its refit, or the descriptor decides among all of them, the best included.
    bool first_strict = false;  // options[0] is the best fit's, with the strict share after its refit
    for (const Fit& f : fits) {
      if (f.inliers < relaxed || static_cast<int>(options.size()) >= o.lbd_candidates) break;
      const double mid = f.alpha + f.beta * y_mid;
      if (std::any_of(mids.begin(), mids.end(), [&](double x) { return std::fabs(x - mid) <= 2 * o.inlier_px; }))
        continue;
      mids.push_back(mid);
      const auto d = refine(samples, search, f, a, relaxed, max_disp, o);
      if (d) options.emplace_back(d->d_start, d->d_end);
      if (d && &f == &fits[0]) first_strict = d->inliers >= needed;
    }
    if (options.empty()) continue;
    // The rows decide alone when one explanation has the strict share and no other as many rows.
    if (first_strict && fits[0].inliers >= needed &&
        fits[0].inliers > second_inliers(fits, mids[0], y_mid, o.inlier_px)) {
      out.push_back(make_stereo_line_match(i, -1, 0, a, options[0].first, options[0].second, calib));
      continue;
    }
    pending.push_back({i, std::move(options)});
  }
  if (pending.empty()) return out;

  // The descriptor decides the rest, in one pass over the right image's gradient.
  const features::LineGradient gradient = features::compute_line_gradient(right, o.lbd_scale);
  std::vector<features::LineSegment> segments;
  for (const auto& p : pending) {
    const features::LineSegment& a = L.lines[static_cast<std::size_t>(p.left)];
    for (const auto& [ds, de] : p.options) {
      features::LineSegment b = a;
      b.start.x -= static_cast<float>(ds);
      b.end.x -= static_cast<float>(de);
      segments.push_back(b);
    }
  }
  const cv::Mat descriptors = features::describe_lines(gradient, segments, o.lbd);
  int row = 0;
  for (const auto& p : pending) {
    int best = INT_MAX, second = INT_MAX;
    std::size_t pick = 0;
    for (std::size_t k = 0; k < p.options.size(); ++k, ++row) {
      const int h = features::hamming_distance(L.descriptors.ptr<uint8_t>(p.left), descriptors.ptr<uint8_t>(row));
      if (h < best) {
        second = best;
        best = h;
        pick = k;
      } else if (h < second) {
        second = h;
      }
    }
    if (best > mo.max_hamming || (second != INT_MAX && best >= mo.ratio * second)) continue;
    const features::LineSegment& a = L.lines[static_cast<std::size_t>(p.left)];
    out.push_back(make_stereo_line_match(p.left, -1, best, a, p.options[pick].first, p.options[pick].second, calib));
  }
  std::sort(out.begin(), out.end(), [](const StereoLineMatch& x, const StereoLineMatch& y) { return x.left < y.left; });
  return out;
}

}  // namespace plslam::matching
