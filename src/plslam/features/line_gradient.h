#pragma once
// Image gradient shared by the line detector and the LBD descriptor, so one Sobel pass serves
// both. It lives at the detector's working scale; `scale` maps its pixels to full resolution.
#include <opencv2/core.hpp>

namespace plslam::features {

struct LineGradient {
  cv::Mat gx, gy;     // CV_16S Sobel 3x3 derivatives
  cv::Mat magnitude;  // CV_32F sqrt(gx^2 + gy^2)
  double scale = 1.0; // working image = full image resized by `scale`

  // Full-resolution pixel coordinate of a working-image pixel and back (pixel centres at
  // integers; an INTER_AREA downscale by 1/2 maps pixels 2i, 2i+1 onto i).
  cv::Point2f to_full(cv::Point2f p) const {
    return {static_cast<float>((p.x + 0.5) / scale - 0.5), static_cast<float>((p.y + 0.5) / scale - 0.5)};
  }
  cv::Point2f to_working(cv::Point2f p) const {
    return {static_cast<float>((p.x + 0.5) * scale - 0.5), static_cast<float>((p.y + 0.5) * scale - 0.5)};
  }
};

// Resizes `grey` (8-bit, one channel) by `scale` (INTER_AREA when shrinking) and computes the
// gradient there. Throws std::invalid_argument for an empty or non-8-bit image.
LineGradient compute_line_gradient(const cv::Mat& grey, double scale);

}  // namespace plslam::features
