#include "plslam/features/line_descriptor.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace plslam::features {

namespace detail {
namespace {
// The one fixed order in which both versions add their four lanes.
void add_lanes(const float lanes[4][4], float sums[4]) {
  for (int c = 0; c < 4; ++c) sums[c] = (lanes[c][0] + lanes[c][1]) + (lanes[c][2] + lanes[c][3]);
}
}  // namespace

// Four lanes, each adding every fourth sample, combined in a fixed order: the SSE2 and the
// portable code give the same floats. With one chain of additions per sum the loop was
// latency-bound, and its max() compiled to branches that the random signs of texture mispredict:
// 3.0 ms for the ~500 lines of a KITTI frame, 1.0 ms now.
void positive_negative_sums_portable(const float* gx, const float* gy, int count, cv::Point2f n, cv::Point2f d,
                                     float sums[4]) {
  float lanes[4][4] = {};  // [sum][lane]
  for (int k = 0; k < count; k += 4) {
    for (int l = 0; l < 4; ++l) {
      const float dp = gx[k + l] * n.x + gy[k + l] * n.y, dl = gx[k + l] * d.x + gy[k + l] * d.y;
      // As _mm_max_ps(v, 0): v > 0 ? v : +0; and -v as 0 - v.
      lanes[0][l] += dp > 0.f ? dp : 0.f;
      lanes[1][l] += 0.f - dp > 0.f ? 0.f - dp : 0.f;
      lanes[2][l] += dl > 0.f ? dl : 0.f;
      lanes[3][l] += 0.f - dl > 0.f ? 0.f - dl : 0.f;
    }
  }
  add_lanes(lanes, sums);
}

void positive_negative_sums(const float* gx, const float* gy, int count, cv::Point2f n, cv::Point2f d,
                            float sums[4]) {
#if defined(__SSE2__)
  const __m128 nx = _mm_set1_ps(n.x), ny = _mm_set1_ps(n.y), dx = _mm_set1_ps(d.x), dy = _mm_set1_ps(d.y);
  const __m128 zero = _mm_setzero_ps();
  __m128 s0 = zero, s1 = zero, s2 = zero, s3 = zero;
  for (int k = 0; k < count; k += 4) {
    const __m128 x = _mm_loadu_ps(gx + k), y = _mm_loadu_ps(gy + k);
    const __m128 dp = _mm_add_ps(_mm_mul_ps(x, nx), _mm_mul_ps(y, ny));
    const __m128 dl = _mm_add_ps(_mm_mul_ps(x, dx), _mm_mul_ps(y, dy));
    s0 = _mm_add_ps(s0, _mm_max_ps(dp, zero));
    s1 = _mm_add_ps(s1, _mm_max_ps(_mm_sub_ps(zero, dp), zero));
    s2 = _mm_add_ps(s2, _mm_max_ps(dl, zero));
    s3 = _mm_add_ps(s3, _mm_max_ps(_mm_sub_ps(zero, dl), zero));
  }
  float lanes[4][4];
  _mm_storeu_ps(lanes[0], s0);
  _mm_storeu_ps(lanes[1], s1);
  _mm_storeu_ps(lanes[2], s2);
  _mm_storeu_ps(lanes[3], s3);
  add_lanes(lanes, sums);
#else
  positive_negative_sums_portable(gx, gy, count, n, d, sums);
#endif
}

}  // namespace detail

namespace {

// Band pairs by increasing separation: nearby bands see nearly the same surface, so their
// comparisons are the most repeatable bits.
std::vector<std::pair<int, int>> band_pairs(int m) {
  std::vector<std::pair<int, int>> p;
  for (int sep = 1; sep < m; ++sep)
    for (int i = 0; i + sep < m; ++i) p.emplace_back(i, i + sep);
  return p;
}

// Gaussian weights depend only on the options: global per row (distance to the line) and local
// per (band, row in the band's 3-band window). Computed once per call, not per line.
struct LbdWeights {
  std::vector<float> global;               // R
  std::vector<std::vector<double>> local;  // m x (rows r0..r1)
  explicit LbdWeights(const LbdOptions& o) {
    const int m = o.bands, w = o.band_width, R = m * w;
    const float sigma_g = 0.5f * (R - 1), sigma_l = static_cast<float>(w);
    for (int r = 0; r < R; ++r) {
      const float off = r - 0.5f * (R - 1);
      global.push_back(std::exp(-off * off / (2 * sigma_g * sigma_g)));
    }
    for (int j = 0; j < m; ++j) {
      const float centre = j * w + 0.5f * (w - 1);
      std::vector<double> l;
      for (int r = std::max(0, (j - 1) * w); r < std::min(R, (j + 2) * w); ++r) {
        const float dr = r - centre;
        l.push_back(std::exp(-dr * dr / (2 * sigma_l * sigma_l)));
      }
      local.push_back(std::move(l));
    }
  }
};

// Band descriptors (m x 8: mean of 4 row sums, std of 4 row sums) for one segment.
void band_descriptors(const LineGradient& g, const LineSegment& s, const LbdOptions& o, const LbdWeights& wt,
                      float* bd) {
  const int m = o.bands, w = o.band_width, R = m * w;
  const int W = g.gx.cols, H = g.gx.rows;
  const cv::Point2f a = g.to_working(s.start), b = g.to_working(s.end);
  cv::Point2f d = b - a;
  const float len = static_cast<float>(cv::norm(d));
  d = len > 0 ? d / len : cv::Point2f(1, 0);
  const cv::Point2f n(-d.y, d.x);  // towards the bright side
  const int K = std::clamp(static_cast<int>(len) + 1, 2, o.max_samples_along);
  const cv::Point2f step = d * (len / (K - 1));

  const short* gxp = g.gx.ptr<short>();
  const short* gyp = g.gy.ptr<short>();
  const std::size_t gstride = g.gx.step1();
  // 16.16 fixed-point steps along the row, the same for every row.
  const int32_t sx = static_cast<int32_t>(std::lround(step.x * 65536.f));
  const int32_t sy = static_cast<int32_t>(std::lround(step.y * 65536.f));
  // Each row's samples, padded with zero gradients to a multiple of 4 (they add +0 to every sum).
  const int K4 = (K + 3) / 4 * 4;
  std::vector<float> sgx(static_cast<std::size_t>(K4), 0.f), sgy(static_cast<std::size_t>(K4), 0.f);
  // Row sums of (d_perp+, d_perp-, d_par+, d_par-), globally weighted, per sample.
  std::vector<float> rows(static_cast<std::size_t>(R) * 4, 0.f);
  for (int r = 0; r < R; ++r) {
    const float off = r - 0.5f * (R - 1);
    const float wg = wt.global[r] / K;
    cv::Point2f p = a + n * off;
    const cv::Point2f q = p + step * static_cast<float>(K - 1);
    if (std::min(p.x, q.x) >= 0 && std::min(p.y, q.y) >= 0 && std::max(p.x, q.x) <= W - 1 &&
        std::max(p.y, q.y) <= H - 1) {
      // Row inside the image: fixed-point stepping, floor(x + 0.5) rounds.
      int32_t fx = static_cast<int32_t>((p.x + 0.5f) * 65536.f), fy = static_cast<int32_t>((p.y + 0.5f) * 65536.f);
      for (int k = 0; k < K; ++k, fx += sx, fy += sy) {
        const std::size_t at = static_cast<std::size_t>(std::min(fy >> 16, H - 1)) * gstride +
                               static_cast<std::size_t>(std::min(fx >> 16, W - 1));
        sgx[static_cast<std::size_t>(k)] = gxp[at];
        sgy[static_cast<std::size_t>(k)] = gyp[at];
      }
    } else {
      for (int k = 0; k < K; ++k, p += step) {
        const std::size_t at = static_cast<std::size_t>(std::clamp(cvRound(p.y), 0, H - 1)) * gstride +
                               static_cast<std::size_t>(std::clamp(cvRound(p.x), 0, W - 1));
        sgx[static_cast<std::size_t>(k)] = gxp[at];
        sgy[static_cast<std::size_t>(k)] = gyp[at];
      }
    }
    float sums[4];
    detail::positive_negative_sums(sgx.data(), sgy.data(), K4, n, d, sums);
    float* row = &rows[static_cast<std::size_t>(r) * 4];
    for (int c = 0; c < 4; ++c) row[c] = sums[c] * wg;
  }
  for (int j = 0; j < m; ++j) {
    const int r0 = std::max(0, (j - 1) * w), r1 = std::min(R, (j + 2) * w);
    double sw = 0, mean[4] = {0, 0, 0, 0}, sq[4] = {0, 0, 0, 0};
    for (int r = r0; r < r1; ++r) {
      const double wl = wt.local[j][r - r0];
      sw += wl;
      for (int c = 0; c < 4; ++c) {
        const double v = rows[static_cast<std::size_t>(r) * 4 + c];
        mean[c] += wl * v;
        sq[c] += wl * v * v;
      }
    }
    for (int c = 0; c < 4; ++c) {
      const double mu = mean[c] / sw;
      bd[j * 8 + c] = static_cast<float>(mu);
      bd[j * 8 + 4 + c] = static_cast<float>(std::sqrt(std::max(0.0, sq[c] / sw - mu * mu)));
    }
  }
  // Normalise the mean and std parts separately, clamp large entries, renormalise (as LBD does
  // against non-linear illumination).
  for (int part = 0; part < 2; ++part) {
    for (int pass = 0; pass < 2; ++pass) {
      double nn = 0;
      for (int j = 0; j < m; ++j)
        for (int c = 0; c < 4; ++c) nn += double(bd[j * 8 + part * 4 + c]) * bd[j * 8 + part * 4 + c];
      const float inv = nn > 0 ? static_cast<float>(1.0 / std::sqrt(nn)) : 0.f;
      for (int j = 0; j < m; ++j)
        for (int c = 0; c < 4; ++c) {
          float& v = bd[j * 8 + part * 4 + c];
          v *= inv;
          if (pass == 0) v = std::min(v, 0.4f);
        }
    }
  }
}

void check(const LineGradient& g, const LbdOptions& o) {
  if (g.gx.empty() || g.gx.type() != CV_16S) throw std::invalid_argument("describe_lines: empty gradient");
  if (o.bands < 2 || o.band_width < 1 || o.max_samples_along < 2)
    throw std::invalid_argument("describe_lines: bad LBD options");
}

}  // namespace

cv::Mat describe_lines_float(const LineGradient& g, const std::vector<LineSegment>& segs, const LbdOptions& o) {
  check(g, o);
  cv::Mat out(static_cast<int>(segs.size()), o.bands * 8, CV_32F);
  const LbdWeights wt(o);
  for (int i = 0; i < out.rows; ++i) band_descriptors(g, segs[i], o, wt, out.ptr<float>(i));
  return out;
}

cv::Mat describe_lines(const LineGradient& g, const std::vector<LineSegment>& segs, const LbdOptions& o) {
  check(g, o);
  const auto pairs = band_pairs(o.bands);
  if (pairs.size() * 8 < kLbdBytes * 8) throw std::invalid_argument("describe_lines: too few bands for 256 bits");
  cv::Mat out(static_cast<int>(segs.size()), kLbdBytes, CV_8U, cv::Scalar(0));
  std::vector<float> bd(static_cast<std::size_t>(o.bands) * 8);
  const LbdWeights wt(o);
  for (int i = 0; i < out.rows; ++i) {
    band_descriptors(g, segs[i], o, wt, bd.data());
    uint8_t* bits = out.ptr<uint8_t>(i);
    for (int p = 0; p < kLbdBytes; ++p) {
      const auto [bi, bj] = pairs[p];
      uint8_t byte = 0;
      for (int c = 0; c < 8; ++c) byte |= static_cast<uint8_t>((bd[bi * 8 + c] > bd[bj * 8 + c]) << c);
      bits[p] = byte;
    }
  }
  return out;
}

}  // namespace plslam::features
