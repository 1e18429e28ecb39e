#pragma once
// FAST-9 corners (9 contiguous pixels of the 16-pixel Bresenham circle of radius 3 all brighter
// than centre + t or all darker than centre - t) with non-maximum suppression by score in a 3x3
// window: the same keypoints, order and scores as cv::FAST(image, kps, t, true) (tested on real
// images), 3-5x faster. The speed comes from computing the score itself, branch-free, for 16 or
// 32 pixels at once: the score is max over arcs of the min absolute difference along the arc,
// and a pixel is a corner exactly when that value exceeds t, so detection needs no separate
// segment test and no per-corner scalar scoring as in OpenCV.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::features {

enum class FastImpl {
  kAuto,    // the fastest one the CPU supports (AVX2, else SSE2, else scalar)
  kAvx2,    // 32 pixels per step
  kSse2,    // 16 pixels per step (x86-64 baseline)
  kScalar,  // portable reference
  kOpenCv,  // cv::FAST, kept selectable for comparisons
};

// FAST corners in a compact layout (structure of arrays): 5 bytes per corner instead of a 28-byte
// cv::KeyPoint, so that the spatial distributions, which read every candidate, stream little
// memory. Coordinates are whole pixels below 65536.
struct FastCorners {
  std::vector<uint32_t> position;  // y << 16 | x
  std::vector<uint8_t> score;      // the FAST score (cv::KeyPoint::response)

  static uint32_t pack(int x, int y) { return static_cast<uint32_t>(y) << 16 | static_cast<uint32_t>(x); }
  static int x_of(uint32_t p) { return static_cast<int>(p & 0xFFFFu); }
  static int y_of(uint32_t p) { return static_cast<int>(p >> 16); }

  std::size_t size() const { return position.size(); }
  bool empty() const { return position.empty(); }
  void clear() {
    position.clear();
    score.clear();
  }
  void reserve(std::size_t n) {
    position.reserve(n);
    score.reserve(n);
  }
  void resize(std::size_t n) {
    position.resize(n);
    score.resize(n);
  }
  void push_back(uint32_t packed, uint8_t s) {
    position.push_back(packed);
    score.push_back(s);
  }
  int x(std::size_t i) const { return x_of(position[i]); }
  int y(std::size_t i) const { return y_of(position[i]); }
  // As detect_fast's cv::KeyPoint: (x, y), size 7, angle -1, response = score.
  cv::KeyPoint keypoint(std::size_t i) const;
  std::vector<cv::KeyPoint> keypoints() const;
  // From keypoints at whole-pixel positions in [0, 65536)^2 with integer responses in [0, 256)
  // (cv::FAST's); throws std::invalid_argument otherwise.
  static FastCorners from_keypoints(const std::vector<cv::KeyPoint>& keypoints);
};

const char* to_string(FastImpl impl);
FastImpl parse_fast_impl(const std::string& name);  // auto|avx2|sse2|scalar|opencv, else InputError
bool fast_impl_available(FastImpl impl);
// kAuto resolved to the implementation it runs on this CPU.
FastImpl resolve_fast_impl(FastImpl impl);

// Corners of `image` (8-bit grey, may be a view) in [3, cols-3) x [3, rows-3), row by row, as
// cv::KeyPoint(x, y, size 7, angle -1, response = score). The score is the largest threshold at
// which the pixel is still a corner. Throws std::invalid_argument when `impl` is not available.
void detect_fast(const cv::Mat& image, int threshold, std::vector<cv::KeyPoint>& keypoints,
                 FastImpl impl = FastImpl::kAuto);
// The same corners, in the same order, in the compact layout (the image must be narrower and
// lower than 65536 pixels).
void detect_fast(const cv::Mat& image, int threshold, FastCorners& corners, FastImpl impl = FastImpl::kAuto);

// Score of one pixel (at least 3 px inside the image) by the definition, or -1 when it is not a
// corner at `threshold`; for tests.
int fast_corner_score(const cv::Mat& image, int x, int y, int threshold);

}  // namespace plslam::features
