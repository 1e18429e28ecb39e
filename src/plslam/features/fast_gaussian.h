#pragma once
// The 7x7, sigma 2 Gaussian blur BRIEF samples from, in 8-bit fixed point. OpenCV's general
// GaussianBlur costs about 3x more here (it dominated descriptor time); two plain separable
// passes that the compiler vectorises are within 1-2 grey levels of it.
#include <opencv2/core.hpp>

namespace plslam::features {

// Blurs `rect` of `src` into `dst` (rect.size(), CV_8U). The 3 pixels around `rect` must lie
// inside `src`: they serve as the filter's border (a padded pyramid level provides them).
void gaussian_blur_7x7(const cv::Mat& src, const cv::Rect& rect, cv::Mat& dst);

namespace detail {
// The same blur compiled for baseline x86-64 only; gaussian_blur_7x7 runs an AVX2 build of the
// same code where the CPU has it. Both give the same bytes.
void gaussian_blur_7x7_baseline(const cv::Mat& src, const cv::Rect& rect, cv::Mat& dst);
}  // namespace detail

}  // namespace plslam::features
