#pragma once
// Synthetic images for the point front-end tests: a smooth multi-scale random texture (rich in
// FAST corners at every pyramid level) and stereo pairs of fronto-parallel planes.
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace plslam::test {

// Deterministic texture: blurred noise at three scales, stretched to 0..255. Returned as CV_32F
// so it can be resampled at sub-pixel positions without quantisation.
inline cv::Mat points_texture_f32(cv::Size size, uint64_t seed = 7) {
  cv::RNG rng(seed);
  cv::Mat sum = cv::Mat::zeros(size, CV_32F);
  const double sigmas[] = {1.2, 3.0, 8.0};
  const double weights[] = {1.0, 1.0, 1.6};
  for (int i = 0; i < 3; ++i) {
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::GaussianBlur(noise, noise, cv::Size(0, 0), sigmas[i]);
    cv::normalize(noise, noise, -1.0, 1.0, cv::NORM_MINMAX);
    sum += noise * weights[i];
  }
  cv::normalize(sum, sum, 10.0, 245.0, cv::NORM_MINMAX);
  return sum;
}

inline cv::Mat points_texture(cv::Size size, uint64_t seed = 7) {
  cv::Mat out;
  points_texture_f32(size, seed).convertTo(out, CV_8U);
  return out;
}

// A rectified pair seeing fronto-parallel planes, one per horizontal band of rows, so there is
// no occlusion: right(x, y) = left(x + d(y), y) with d = bf / z of the band.
struct SyntheticStereo {
  cv::Mat left, right;
  std::vector<double> row_depth;  // true depth of every row
};

inline SyntheticStereo synthetic_plane_stereo(cv::Size size, double bf, const std::vector<double>& band_depths,
                                              uint64_t seed = 11) {
  const int margin = 200;
  const cv::Mat tex = points_texture_f32(cv::Size(size.width + margin, size.height), seed);
  SyntheticStereo s;
  s.row_depth.resize(static_cast<std::size_t>(size.height));
  cv::Mat map_lx(size, CV_32F), map_rx(size, CV_32F), map_y(size, CV_32F);
  const int bands = static_cast<int>(band_depths.size());
  for (int y = 0; y < size.height; ++y) {
    const double z = band_depths[static_cast<std::size_t>(std::min(bands - 1, y * bands / size.height))];
    s.row_depth[static_cast<std::size_t>(y)] = z;
    const double d = bf / z;
    for (int x = 0; x < size.width; ++x) {
      map_lx.at<float>(y, x) = static_cast<float>(x + margin / 2);
      map_rx.at<float>(y, x) = static_cast<float>(x + margin / 2 + d);
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  }
  cv::Mat lf, rf;
  cv::remap(tex, lf, map_lx, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  cv::remap(tex, rf, map_rx, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  lf.convertTo(s.left, CV_8U);
  rf.convertTo(s.right, CV_8U);
  return s;
}

}  // namespace plslam::test
