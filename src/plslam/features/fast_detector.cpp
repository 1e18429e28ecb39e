#include "plslam/features/fast_detector.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <opencv2/features2d.hpp>

#include "plslam/core/cpu_features.h"
#include "plslam/core/error.h"
#include "plslam/core/pixel_kernel.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PLSLAM_FAST_X86 1
#endif

namespace plslam::features {
namespace {

// The 16-pixel Bresenham circle of radius 3, in circular order (the start and direction do not
// matter: both the segment test and the score are taken over all arcs).
constexpr std::array<std::array<int, 2>, 16> kRing = {{{0, 3}, {1, 3}, {2, 2}, {3, 1}, {3, 0}, {3, -1}, {2, -2}, {1, -3},
                                                      {0, -3}, {-1, -3}, {-2, -2}, {-3, -1}, {-3, 0}, {-3, 1}, {-2, 2}, {-1, 3}}};
constexpr int kRadius = 3;

std::array<std::ptrdiff_t, 16> ring_offsets(std::ptrdiff_t step) {
  std::array<std::ptrdiff_t, 16> off{};
  for (std::size_t k = 0; k < 16; ++k) off[k] = kRing[k][1] * step + kRing[k][0];
  return off;
}

namespace scalar {

// max over arcs of 9 of the min difference along the arc, brighter or darker.
[[gnu::always_inline]] inline int raw_value(const uint8_t* p, const std::ptrdiff_t* ring) {
  std::array<int, 16> bright{}, dark{};
  for (std::size_t k = 0; k < 16; ++k) {
    const int d = static_cast<int>(p[ring[k]]) - static_cast<int>(p[0]);
    bright[k] = std::max(d, 0);
    dark[k] = std::max(-d, 0);
  }
  int best = 0;
  for (std::size_t k = 0; k < 16; ++k) {
    int mb = 255, md = 255;
    for (std::size_t j = 0; j < 9; ++j) {
      mb = std::min(mb, bright[(k + j) & 15]);
      md = std::min(md, dark[(k + j) & 15]);
    }
    best = std::max(best, std::max(mb, md));
  }
  return best;
}

PLSLAM_PIXEL_KERNEL void score_run(const uint8_t* p, const std::ptrdiff_t* ring, int n, uint8_t threshold, uint8_t* out) {
  for (int x = 0; x < n; ++x) {
    const int raw = raw_value(p + x, ring);
    out[x] = static_cast<uint8_t>(raw > threshold ? raw - 1 : 0);
  }
}

PLSLAM_PIXEL_KERNEL int nms_run(const uint8_t* s0, const uint8_t* s1, const uint8_t* s2, int x0, int x1, int* xs) {
  int n = 0;
  for (int x = x0; x < x1; ++x) {
    const uint8_t s = s1[x];
    if (s > s0[x - 1] && s > s0[x] && s > s0[x + 1] && s > s1[x - 1] && s > s1[x + 1] && s > s2[x - 1] &&
        s > s2[x] && s > s2[x + 1])
      xs[n++] = x;
  }
  return n;
}

}  // namespace scalar

#ifdef PLSLAM_FAST_X86
namespace sse2 {
struct V {
  using T = __m128i;
  static constexpr int kLanes = 16;
  [[gnu::always_inline]] static T load(const uint8_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); }
  [[gnu::always_inline]] static void store(uint8_t* p, T v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
  [[gnu::always_inline]] static T set1(uint8_t v) { return _mm_set1_epi8(static_cast<char>(v)); }
  [[gnu::always_inline]] static T subs(T a, T b) { return _mm_subs_epu8(a, b); }
  [[gnu::always_inline]] static T sub(T a, T b) { return _mm_sub_epi8(a, b); }
  [[gnu::always_inline]] static T min(T a, T b) { return _mm_min_epu8(a, b); }
  [[gnu::always_inline]] static T max(T a, T b) { return _mm_max_epu8(a, b); }
  [[gnu::always_inline]] static T eq_zero(T a) { return _mm_cmpeq_epi8(a, _mm_setzero_si128()); }
  [[gnu::always_inline]] static T andnot(T a, T b) { return _mm_andnot_si128(a, b); }
  [[gnu::always_inline]] static uint32_t nonzero_mask(T a) { return ~static_cast<uint32_t>(_mm_movemask_epi8(eq_zero(a))) & 0xFFFFu; }
  [[gnu::always_inline]] static bool any_nonzero(T a) { return _mm_movemask_epi8(eq_zero(a)) != 0xFFFF; }
};
#include "plslam/features/fast_kernel.inc"
}  // namespace sse2

// AVX2 for these functions only (chosen at run time); clang spells the pragma differently (the
// fuzz targets build the library with clang).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace avx2 {
struct V {
  using T = __m256i;
  static constexpr int kLanes = 32;
  [[gnu::always_inline]] static T load(const uint8_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  [[gnu::always_inline]] static void store(uint8_t* p, T v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  [[gnu::always_inline]] static T set1(uint8_t v) { return _mm256_set1_epi8(static_cast<char>(v)); }
  [[gnu::always_inline]] static T subs(T a, T b) { return _mm256_subs_epu8(a, b); }
  [[gnu::always_inline]] static T sub(T a, T b) { return _mm256_sub_epi8(a, b); }
  [[gnu::always_inline]] static T min(T a, T b) { return _mm256_min_epu8(a, b); }
  [[gnu::always_inline]] static T max(T a, T b) { return _mm256_max_epu8(a, b); }
  [[gnu::always_inline]] static T eq_zero(T a) { return _mm256_cmpeq_epi8(a, _mm256_setzero_si256()); }
  [[gnu::always_inline]] static T andnot(T a, T b) { return _mm256_andnot_si256(a, b); }
  [[gnu::always_inline]] static uint32_t nonzero_mask(T a) { return ~static_cast<uint32_t>(_mm256_movemask_epi8(eq_zero(a))); }
  [[gnu::always_inline]] static bool any_nonzero(T a) { return !_mm256_testz_si256(a, a); }
};
#include "plslam/features/fast_kernel.inc"
}  // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

struct Kernels {
  int lanes;  // score_run needs at least this many pixels
  void (*score_run)(const uint8_t*, const std::ptrdiff_t*, int, uint8_t, uint8_t*);
  int (*nms_run)(const uint8_t*, const uint8_t*, const uint8_t*, int, int, int*);
};

bool cpu_has_avx2() {
#ifdef PLSLAM_FAST_X86
  return core::cpu_has_avx2();
#else
  return false;
#endif
}

Kernels kernels(FastImpl impl) {
  switch (impl) {
#ifdef PLSLAM_FAST_X86
    case FastImpl::kAvx2:
      return {avx2::V::kLanes, avx2::score_run, avx2::nms_run};
    case FastImpl::kSse2:
      return {sse2::V::kLanes, sse2::score_run, sse2::nms_run};
#endif
    default:
      return {1, scalar::score_run, scalar::nms_run};
  }
}

}  // namespace

const char* to_string(FastImpl impl) {
  switch (impl) {
    case FastImpl::kAuto: return "auto";
    case FastImpl::kAvx2: return "avx2";
    case FastImpl::kSse2: return "sse2";
    case FastImpl::kScalar: return "scalar";
    case FastImpl::kOpenCv: return "opencv";
  }
  return "?";
}

FastImpl parse_fast_impl(const std::string& name) {
  for (FastImpl i : {FastImpl::kAuto, FastImpl::kAvx2, FastImpl::kSse2, FastImpl::kScalar, FastImpl::kOpenCv})
    if (name == to_string(i)) return i;
  throw InputError("", "unknown FAST implementation '" + name + "' (expected auto, avx2, sse2, scalar or opencv)");
}

bool fast_impl_available(FastImpl impl) {
  switch (impl) {
    case FastImpl::kAvx2: return cpu_has_avx2();
#ifdef PLSLAM_FAST_X86
    case FastImpl::kSse2: return true;
#else
    case FastImpl::kSse2: return false;
#endif
    default: return true;
  }
}

FastImpl resolve_fast_impl(FastImpl impl) {
  if (impl != FastImpl::kAuto) return impl;
  if (fast_impl_available(FastImpl::kAvx2)) return FastImpl::kAvx2;
  if (fast_impl_available(FastImpl::kSse2)) return FastImpl::kSse2;
  return FastImpl::kScalar;
}

cv::KeyPoint FastCorners::keypoint(std::size_t i) const {
  return {cv::Point2f(static_cast<float>(x(i)), static_cast<float>(y(i))), 7.f, -1.f, static_cast<float>(score[i])};
}

std::vector<cv::KeyPoint> FastCorners::keypoints() const {
  std::vector<cv::KeyPoint> out;
  out.reserve(size());
  for (std::size_t i = 0; i < size(); ++i) out.push_back(keypoint(i));
  return out;
}

FastCorners FastCorners::from_keypoints(const std::vector<cv::KeyPoint>& keypoints) {
  FastCorners out;
  out.reserve(keypoints.size());
  for (const auto& k : keypoints) {
    const auto x = static_cast<int>(k.pt.x), y = static_cast<int>(k.pt.y), r = static_cast<int>(k.response);
    const bool whole = k.pt.x >= 0.f && k.pt.y >= 0.f && k.pt.x < 65536.f && k.pt.y < 65536.f && k.response >= 0.f &&
                       k.response < 256.f && static_cast<float>(x) == k.pt.x && static_cast<float>(y) == k.pt.y &&
                       static_cast<float>(r) == k.response;
    if (!whole) throw std::invalid_argument("FastCorners: keypoint not at a whole pixel or without an integer score");
    out.push_back(pack(x, y), static_cast<uint8_t>(r));
  }
  return out;
}

void detect_fast(const cv::Mat& image, int threshold, FastCorners& corners, FastImpl impl) {
  corners.clear();
  impl = resolve_fast_impl(impl);
  if (!fast_impl_available(impl)) throw std::invalid_argument(std::string("FAST implementation not available: ") + to_string(impl));
  if (image.type() != CV_8UC1) throw std::invalid_argument("detect_fast needs an 8-bit grey image");
  if (image.cols > 65536 || image.rows > 65536) throw std::invalid_argument("detect_fast: image too large for FastCorners");
  if (impl == FastImpl::kOpenCv) {
    std::vector<cv::KeyPoint> keypoints;
    cv::FAST(image, keypoints, threshold, true);
    corners = FastCorners::from_keypoints(keypoints);
    return;
  }
  const int rows = image.rows, cols = image.cols;
  if (rows <= 2 * kRadius || cols <= 2 * kRadius) return;
  const auto t = static_cast<uint8_t>(std::clamp(threshold, 0, 255));
  const auto ring = ring_offsets(static_cast<std::ptrdiff_t>(image.step));
  Kernels k = kernels(impl);
  const int n = cols - 2 * kRadius;  // scored columns per row: [3, cols - 3)
  if (n < k.lanes) k = kernels(FastImpl::kScalar);

  // Three score rows (above, current, below), zero outside [3, cols - 3) so that suppression at
  // the edges compares with zeros as cv::FAST does; 64 spare bytes for full-width SIMD reads.
  const int stride = cols + 64;
  std::vector<uint8_t> scores(static_cast<std::size_t>(3 * stride), 0);
  auto row = [&](int y) { return scores.data() + static_cast<std::ptrdiff_t>(y % 3) * stride; };
  std::vector<int> xs(static_cast<std::size_t>(cols));
  for (int y = kRadius; y <= rows - kRadius; ++y) {
    if (y < rows - kRadius) {
      k.score_run(image.ptr<uint8_t>(y) + kRadius, ring.data(), n, t, row(y) + kRadius);
    } else {
      std::memset(row(y), 0, static_cast<std::size_t>(stride));
    }
    if (y == kRadius) continue;
    // Row y - 1 is complete: its neighbours above (y - 2, zero for the first row) and below (y).
    const int found = k.nms_run(row(y - 2), row(y - 1), row(y), kRadius, cols - kRadius, xs.data());
    const uint8_t* s = row(y - 1);
    const uint32_t row_bits = FastCorners::pack(0, y - 1);
    for (int i = 0; i < found; ++i) {
      const int x = xs[static_cast<std::size_t>(i)];
      corners.push_back(row_bits | static_cast<uint32_t>(x), s[x]);
    }
  }
}

void detect_fast(const cv::Mat& image, int threshold, std::vector<cv::KeyPoint>& keypoints, FastImpl impl) {
  keypoints.clear();
  if (resolve_fast_impl(impl) == FastImpl::kOpenCv && fast_impl_available(impl) && image.type() == CV_8UC1) {
    cv::FAST(image, keypoints, threshold, true);
    return;
  }
  FastCorners corners;
  detect_fast(image, threshold, corners, impl);
  keypoints = corners.keypoints();
}

int fast_corner_score(const cv::Mat& image, int x, int y, int threshold) {
  if (image.type() != CV_8UC1 || x < kRadius || y < kRadius || x >= image.cols - kRadius || y >= image.rows - kRadius)
    throw std::invalid_argument("fast_corner_score: pixel too close to the border or not an 8-bit grey image");
  const auto ring = ring_offsets(static_cast<std::ptrdiff_t>(image.step));
  const int raw = scalar::raw_value(image.ptr<uint8_t>(y) + x, ring.data());
  return raw > threshold ? raw - 1 : -1;
}

}  // namespace plslam::features
