#pragma once
// Scale pyramid for ORB features. Every level lives inside a padded buffer (reflect-101 border)
// so that descriptor patches and the Gaussian blur near the image edge read plausible pixels
// instead of stepping outside the allocation.
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::features {

class ImagePyramid {
 public:
  ImagePyramid() = default;

  // Builds `levels` levels, level l being the input shrunk by scale_factor^l (bilinear, each
  // level from the previous one, like ORB-SLAM2). `image` must be 8-bit single channel.
  void build(const cv::Mat& image, int levels, double scale_factor, int border);

  int levels() const { return static_cast<int>(levels_.size()); }
  int border() const { return border_; }
  double scale_factor() const { return scale_factor_; }
  // The level image: a view without the border (the border pixels exist around it).
  const cv::Mat& level(int l) const { return levels_[static_cast<std::size_t>(l)]; }
  // The whole padded buffer of level l.
  const cv::Mat& padded(int l) const { return padded_[static_cast<std::size_t>(l)]; }

  // Nominal scale scale_factor^l: feature size and search radii grow with it.
  double scale(int l) const { return scales_[static_cast<std::size_t>(l)]; }

  // Exact maps between level-0 and level-l pixel coordinates. Level sizes are rounded, so the
  // true ratio is width/width_l (x) and height/height_l (y); pixel centres are aligned as
  // cv::resize aligns them: (x0 + 0.5) = (xl + 0.5) * ratio.
  float to_level_x(float x0, int l) const { return (x0 + 0.5f) / sx_[idx(l)] - 0.5f; }
  float to_level_y(float y0, int l) const { return (y0 + 0.5f) / sy_[idx(l)] - 0.5f; }
  float from_level_x(float xl, int l) const { return (xl + 0.5f) * sx_[idx(l)] - 0.5f; }
  float from_level_y(float yl, int l) const { return (yl + 0.5f) * sy_[idx(l)] - 0.5f; }

 private:
  static std::size_t idx(int l) { return static_cast<std::size_t>(l); }

  int border_ = 0;
  double scale_factor_ = 1.0;
  std::vector<cv::Mat> padded_;
  std::vector<cv::Mat> levels_;
  std::vector<double> scales_;
  std::vector<float> sx_, sy_;
};

}  // namespace plslam::features
