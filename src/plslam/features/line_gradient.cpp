#include "plslam/features/line_gradient.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace plslam::features {

LineGradient compute_line_gradient(const cv::Mat& grey, double scale) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw std::invalid_argument("compute_line_gradient: need a non-empty 8-bit grey image");
  if (!(scale > 0.0 && scale <= 1.0)) throw std::invalid_argument("compute_line_gradient: scale must be in (0, 1]");
  LineGradient g;
  g.scale = scale;
  cv::Mat work = grey;
  if (scale < 1.0) {
    const cv::Size sz(static_cast<int>(std::lround(grey.cols * scale)), static_cast<int>(std::lround(grey.rows * scale)));
    cv::resize(grey, work, sz, 0, 0, cv::INTER_AREA);
    // Keep the mapping exact for the rounded size.
    g.scale = static_cast<double>(sz.width) / grey.cols;
  }
  cv::Sobel(work, g.gx, CV_16S, 1, 0, 3, 1, 0, cv::BORDER_REPLICATE);
  cv::Sobel(work, g.gy, CV_16S, 0, 1, 3, 1, 0, cv::BORDER_REPLICATE);
  g.magnitude.create(work.size(), CV_32F);
  for (int y = 0; y < work.rows; ++y) {
    const short* px = g.gx.ptr<short>(y);
    const short* py = g.gy.ptr<short>(y);
    float* m = g.magnitude.ptr<float>(y);
    for (int x = 0; x < work.cols; ++x) {
      const float a = px[x], b = py[x];
      m[x] = std::sqrt(a * a + b * b);
    }
  }
  return g;
}

}  // namespace plslam::features
