#pragma once
// FAST-9 corners (9 contiguous pixels of the 16-pixel Bresenham circle of radius 3 all brighter
// than centre + t or all darker than centre - t) with non-maximum suppression by score in a 3x3
// window: the same keypoints, order and scores as cv::FAST(image, kps, t, true) (tested on real
// images), 3-5x faster. The speed comes from computing the score itself, branch-free, for 16 or
// 32 pixels at once: the score is max over arcs of the min absolute difference along the arc,
// and a pixel is a corner exactly when that value exceeds t, so detection needs no separate
// segment test and no per-corner scalar scoring as in OpenCV.
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

// Score of one pixel (at least 3 px inside the image) by the definition, or -1 when it is not a
// corner at `threshold`; for tests.
int fast_corner_score(const cv::Mat& image, int x, int y, int threshold);

}  // namespace plslam::features
