#include "plslam/features/fast_gaussian.h"

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "plslam/core/cpu_features.h"
#include "plslam/core/pixel_kernel.h"

namespace plslam::features {
namespace {

// exp(-x^2 / (2 * 2^2)) for x = 0..3, normalised and scaled to sum to 256.
constexpr int k0 = 56, k1 = 49, k2 = 33, k3 = 18;
static_assert(k0 + 2 * (k1 + k2 + k3) == 256);

// The two passes, written once: compiled below for baseline x86-64 (SSE2, 8 lanes of 16 bits)
// and for AVX2 (16 lanes).
[[gnu::always_inline]] inline void blur_passes(const cv::Mat& src, const cv::Rect& rect, uint8_t* tmp, cv::Mat& dst) {
  const int w = rect.width, h = rect.height;
  // Horizontal pass over the rows the vertical pass needs (3 above and below).
  for (int r = 0; r < h + 6; ++r) {
    const uint8_t* s = src.ptr<uint8_t>(rect.y - 3 + r) + rect.x;
    uint8_t* t = tmp + static_cast<std::size_t>(r) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      // 16-bit lanes suffice (at most 256 * 255 + 128), which doubles the vector width.
      const uint16_t v = static_cast<uint16_t>(k0 * s[x]) + static_cast<uint16_t>(k1 * static_cast<uint16_t>(s[x - 1] + s[x + 1])) +
                         static_cast<uint16_t>(k2 * static_cast<uint16_t>(s[x - 2] + s[x + 2])) +
                         static_cast<uint16_t>(k3 * static_cast<uint16_t>(s[x - 3] + s[x + 3])) + uint16_t{128};
      t[x] = static_cast<uint8_t>(v >> 8);
    }
  }
  const std::size_t ws = static_cast<std::size_t>(w);
  for (int r = 0; r < h; ++r) {
    const uint8_t* c = tmp + static_cast<std::size_t>(r + 3) * ws;
    uint8_t* d = dst.ptr<uint8_t>(r);
    for (int x = 0; x < w; ++x) {
      const uint16_t v = static_cast<uint16_t>(k0 * c[x]) + static_cast<uint16_t>(k1 * static_cast<uint16_t>(c[x - ws] + c[x + ws])) +
                         static_cast<uint16_t>(k2 * static_cast<uint16_t>(c[x - 2 * ws] + c[x + 2 * ws])) +
                         static_cast<uint16_t>(k3 * static_cast<uint16_t>(c[x - 3 * ws] + c[x + 3 * ws])) + uint16_t{128};
      d[x] = static_cast<uint8_t>(v >> 8);
    }
  }
}

PLSLAM_PIXEL_KERNEL void blur_baseline(const cv::Mat& src, const cv::Rect& rect, uint8_t* tmp, cv::Mat& dst) {
  blur_passes(src, rect, tmp, dst);
}
#if defined(__x86_64__)
// Chosen with core::cpu_has_avx2().
__attribute__((target("avx2"))) PLSLAM_PIXEL_KERNEL void blur_avx2(const cv::Mat& src, const cv::Rect& rect, uint8_t* tmp, cv::Mat& dst) {
  blur_passes(src, rect, tmp, dst);
}
#endif

void check_blur_input(const cv::Mat& src, const cv::Rect& rect) {
  if (src.type() != CV_8UC1 || rect.x < 3 || rect.y < 3 || rect.x + rect.width + 3 > src.cols ||
      rect.y + rect.height + 3 > src.rows)
    throw std::invalid_argument("gaussian_blur_7x7: need 8-bit input with 3 pixels around the rectangle");
}

}  // namespace

void gaussian_blur_7x7(const cv::Mat& src, const cv::Rect& rect, cv::Mat& dst) {
  check_blur_input(src, rect);
  dst.create(rect.height, rect.width, CV_8U);
  thread_local std::vector<uint8_t> tmp;
  tmp.resize(static_cast<std::size_t>(rect.width) * static_cast<std::size_t>(rect.height + 6));
#if defined(__x86_64__)
  if (core::cpu_has_avx2()) return blur_avx2(src, rect, tmp.data(), dst);
#endif
  blur_baseline(src, rect, tmp.data(), dst);
}

namespace detail {
void gaussian_blur_7x7_baseline(const cv::Mat& src, const cv::Rect& rect, cv::Mat& dst) {
  check_blur_input(src, rect);
  dst.create(rect.height, rect.width, CV_8U);
  std::vector<uint8_t> tmp(static_cast<std::size_t>(rect.width) * static_cast<std::size_t>(rect.height + 6));
  blur_baseline(src, rect, tmp.data(), dst);
}
}  // namespace detail

}  // namespace plslam::features
