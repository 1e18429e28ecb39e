#include "plslam/features/orb_descriptor.h"

#include <bit>
#include <cmath>
#include <cstring>

#include <opencv2/core/fast_math.hpp>

#include "plslam/core/cpu_features.h"
#include "plslam/core/pixel_kernel.h"

namespace plslam::features {
namespace {

// splitmix64: tiny, fully specified, so the pattern does not depend on the standard library's
// distribution implementations.
struct SplitMix64 {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }  // [0,1)
};

std::array<std::array<int8_t, 4>, 256> make_pattern() {
  SplitMix64 rng{0x5EEDB41EF00Dull};
  const double sigma = 31.0 / 5.0;
  auto gaussian_coordinate = [&]() -> int {
    for (;;) {
      // Box-Muller; one of the pair is enough.
      const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
      const double g = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2) * sigma;
      const long v = std::lround(g);
      if (std::abs(v) <= kBriefPatternHalfExtent) return static_cast<int>(v);
    }
  };
  std::array<std::array<int8_t, 4>, 256> pattern{};
  for (auto& p : pattern) {
    do {
      for (auto& c : p) c = static_cast<int8_t>(gaussian_coordinate());
    } while (p[0] == p[2] && p[1] == p[3]);  // a test of a pixel against itself carries no bit
  }
  return pattern;
}

// Half-widths of the disc rows: umax[v] = largest u with u^2 + v^2 <= r^2 (+0.5 for rounding).
std::array<int, kOrbPatchRadius + 1> make_umax() {
  std::array<int, kOrbPatchRadius + 1> umax{};
  for (int v = 0; v <= kOrbPatchRadius; ++v)
    umax[static_cast<std::size_t>(v)] =
        static_cast<int>(std::floor(std::sqrt(kOrbPatchRadius * kOrbPatchRadius + 0.5 - v * v)));
  return umax;
}

}  // namespace

const std::array<std::array<int8_t, 4>, 256>& brief_pattern() {
  static const auto pattern = make_pattern();
  return pattern;
}

namespace {

// The orientation and the descriptor are written once and compiled twice: for baseline x86-64
// and for AVX2 (twice the vector width for the disc's sums and the pattern's rotation), chosen
// with core::cpu_has_avx2(). Without FMA both round alike.
[[gnu::always_inline]] inline float centroid_angle_impl(const cv::Mat& image, int x, int y) {
  // Every row of the disc as 32 weights over u = -15..16 (zero outside the disc), so each row is
  // one fixed-length multiply-accumulate the compiler vectorises.
  struct Disc {
    alignas(16) int16_t u_weight[2 * kOrbPatchRadius + 1][32];
    alignas(16) int16_t inside[2 * kOrbPatchRadius + 1][32];
  };
  static const Disc disc = [] {
    Disc d{};
    const auto umax = make_umax();
    for (int v = -kOrbPatchRadius; v <= kOrbPatchRadius; ++v) {
      const int half = umax[static_cast<std::size_t>(std::abs(v))];
      for (int k = 0; k < 32; ++k) {
        const int u = k - kOrbPatchRadius;
        const bool in = std::abs(u) <= half;
        d.u_weight[v + kOrbPatchRadius][k] = static_cast<int16_t>(in ? u : 0);
        d.inside[v + kOrbPatchRadius][k] = static_cast<int16_t>(in ? 1 : 0);
      }
    }
    return d;
  }();
  const int step = static_cast<int>(image.step1());
  const uchar* top_left = image.ptr<uchar>(y) + x - kOrbPatchRadius;
  int m10 = 0, m01 = 0;
  for (int r = 0; r <= 2 * kOrbPatchRadius; ++r) {
    const uchar* row = top_left + (r - kOrbPatchRadius) * step;
    int su = 0, s1 = 0;
    for (int k = 0; k < 32; ++k) {
      su += disc.u_weight[r][k] * row[k];
      s1 += disc.inside[r][k] * row[k];
    }
    m10 += su;
    m01 += (r - kOrbPatchRadius) * s1;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

[[gnu::always_inline]] inline void brief_impl(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out) {
  // The pattern as float columns, built once: the rotation below then runs as plain vector code.
  struct Columns {
    alignas(32) float x[512], y[512];
  };
  static const Columns cols = [] {
    Columns c{};
    const auto& p = brief_pattern();
    for (std::size_t i = 0; i < 256; ++i) {
      c.x[2 * i] = p[i][0];
      c.y[2 * i] = p[i][1];
      c.x[2 * i + 1] = p[i][2];
      c.y[2 * i + 1] = p[i][3];
    }
    return c;
  }();
  const float a = angle_deg * static_cast<float>(CV_PI / 180.0);
  const float c = std::cos(a), s = std::sin(a);
  const int step = static_cast<int>(blurred.step1());
  alignas(32) int offset[512];
  // Rounding by truncation of a shifted positive value (|coordinate| < 19), which vectorises
  // without SSE4's round instruction.
  constexpr float kShift = 64.5f;
  for (int i = 0; i < 512; ++i) {
    const int rx = static_cast<int>(cols.x[i] * c - cols.y[i] * s + kShift) - 64;
    const int ry = static_cast<int>(cols.x[i] * s + cols.y[i] * c + kShift) - 64;
    offset[i] = ry * step + rx;
  }
  const uchar* center = blurred.ptr<uchar>(y) + x;
  for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
    const int* o = offset + byte * 16;
    uint8_t v = 0;
    for (int bit = 0; bit < 8; ++bit) v |= static_cast<uint8_t>((center[o[2 * bit]] < center[o[2 * bit + 1]]) << bit);
    out[byte] = v;
  }
}

PLSLAM_PIXEL_KERNEL float centroid_angle_baseline(const cv::Mat& image, int x, int y) { return centroid_angle_impl(image, x, y); }
PLSLAM_PIXEL_KERNEL void brief_baseline(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out) {
  brief_impl(blurred, x, y, angle_deg, out);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) PLSLAM_PIXEL_KERNEL float centroid_angle_avx2(const cv::Mat& image, int x, int y) {
  return centroid_angle_impl(image, x, y);
}
__attribute__((target("avx2"))) PLSLAM_PIXEL_KERNEL void brief_avx2(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out) {
  brief_impl(blurred, x, y, angle_deg, out);
}
#endif

}  // namespace

float intensity_centroid_angle(const cv::Mat& image, int x, int y) {
#if defined(__x86_64__)
  if (core::cpu_has_avx2()) return centroid_angle_avx2(image, x, y);
#endif
  return centroid_angle_baseline(image, x, y);
}

void brief_descriptor(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out) {
#if defined(__x86_64__)
  if (core::cpu_has_avx2()) return brief_avx2(blurred, x, y, angle_deg, out);
#endif
  brief_baseline(blurred, x, y, angle_deg, out);
}

namespace detail {
float intensity_centroid_angle_baseline(const cv::Mat& image, int x, int y) {
  return centroid_angle_baseline(image, x, y);
}
void brief_descriptor_baseline(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out) {
  brief_baseline(blurred, x, y, angle_deg, out);
}
}  // namespace detail

namespace {
inline int hamming_impl(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int i = 0; i < kOrbDescriptorBytes; i += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}
#if defined(__x86_64__)
// Matching calls this millions of times per second. The build targets baseline x86-64, where
// std::popcount is a libgcc call; this copy uses the POPCNT instruction. Dispatch by a flag set
// at start-up: GCC's target_clones would need an ifunc resolver, which crashes under
// ThreadSanitizer.
__attribute__((target("popcnt"))) int hamming_popcnt(const uint8_t* a, const uint8_t* b) {
  return hamming_impl(a, b);
}
const bool kHasPopcnt = (__builtin_cpu_init(), __builtin_cpu_supports("popcnt"));
#endif
}  // namespace

int hamming_distance(const uint8_t* a, const uint8_t* b) {
#if defined(__x86_64__)
  if (kHasPopcnt) return hamming_popcnt(a, b);
#endif
  return hamming_impl(a, b);
}

}  // namespace plslam::features
