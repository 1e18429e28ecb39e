#include "plslam/features/image_pyramid.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace plslam::features {
namespace {

// Fills the border of `padded` around its interior (offset `b`) by reflect-101, in place: a
// copyMakeBorder would need a second buffer and a full copy per level.
void fill_reflect_border(cv::Mat& padded, int b) {
  const int w = padded.cols - 2 * b;
  const int h = padded.rows - 2 * b;
  std::vector<int> src_col(static_cast<std::size_t>(b) * 2);
  for (int i = 0; i < b; ++i) {
    src_col[static_cast<std::size_t>(i)] = b + cv::borderInterpolate(i - b, w, cv::BORDER_REFLECT_101);
    src_col[static_cast<std::size_t>(b + i)] = b + cv::borderInterpolate(w + i, w, cv::BORDER_REFLECT_101);
  }
  for (int y = b; y < b + h; ++y) {
    uchar* row = padded.ptr<uchar>(y);
    for (int i = 0; i < b; ++i) {
      row[i] = row[src_col[static_cast<std::size_t>(i)]];
      row[b + w + i] = row[src_col[static_cast<std::size_t>(b + i)]];
    }
  }
  const std::size_t row_bytes = static_cast<std::size_t>(padded.cols);
  for (int i = 0; i < b; ++i) {
    const int top_src = b + cv::borderInterpolate(i - b, h, cv::BORDER_REFLECT_101);
    const int bottom_src = b + cv::borderInterpolate(h + i, h, cv::BORDER_REFLECT_101);
    std::memcpy(padded.ptr<uchar>(i), padded.ptr<uchar>(top_src), row_bytes);
    std::memcpy(padded.ptr<uchar>(b + h + i), padded.ptr<uchar>(bottom_src), row_bytes);
  }
}

}  // namespace

void ImagePyramid::build(const cv::Mat& image, int levels, double scale_factor, int border) {
  if (image.empty() || image.type() != CV_8UC1) throw std::invalid_argument("ImagePyramid: need a non-empty 8-bit grey image");
  if (levels < 1 || scale_factor <= 1.0 || border < 0) throw std::invalid_argument("ImagePyramid: bad levels/scale/border");
  border_ = border;
  scale_factor_ = scale_factor;
  padded_.resize(static_cast<std::size_t>(levels));
  levels_.resize(static_cast<std::size_t>(levels));
  scales_.resize(static_cast<std::size_t>(levels));
  sx_.resize(static_cast<std::size_t>(levels));
  sy_.resize(static_cast<std::size_t>(levels));
  double s = 1.0;
  for (int l = 0; l < levels; ++l, s *= scale_factor) {
    const std::size_t i = idx(l);
    const int w = std::max(1, static_cast<int>(std::lround(image.cols / s)));
    const int h = std::max(1, static_cast<int>(std::lround(image.rows / s)));
    // Reuse the buffer when the size repeats (the common case frame after frame).
    padded_[i].create(h + 2 * border, w + 2 * border, CV_8UC1);
    levels_[i] = padded_[i](cv::Rect(border, border, w, h));
    if (l == 0) {
      image.copyTo(levels_[i]);
    } else {
      cv::resize(levels_[i - 1], levels_[i], levels_[i].size(), 0, 0, cv::INTER_LINEAR);
    }
    // Reflection needs at least two pixels per side; tiny levels are never used for features.
    if (border > 0 && w > border && h > border) fill_reflect_border(padded_[i], border);
    scales_[i] = s;
    sx_[i] = static_cast<float>(image.cols) / static_cast<float>(w);
    sy_[i] = static_cast<float>(image.rows) / static_cast<float>(h);
  }
}

}  // namespace plslam::features
