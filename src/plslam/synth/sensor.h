#pragma once
// Camera realism applied to a radiance image: exposure (which drifts +-20 % over time),
// mild vignetting, signal-dependent Gaussian noise, and 8-bit quantisation. Deterministic:
// the noise comes from a seeded generator, not from a global random state.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::synth {

class SensorModel {
 public:
  SensorModel(int width, int height, std::uint64_t seed);

  // Relative exposure at time t: smooth, within [0.8, 1.2].
  double exposure(double t) const;
  // Radiance (CV_32F) -> CV_8U grey. `noise_seed` must differ per frame and camera.
  void expose(const cv::Mat& radiance, double exposure, std::uint64_t noise_seed, cv::Mat& out) const;

  static constexpr double kGain = 200.0;  // grey levels per unit radiance at exposure 1

 private:
  int width_, height_;
  std::vector<float> vignette_;     // per pixel gain in (0, 1]
  std::vector<float> gauss_;        // 4096 standard normal samples
  float sigma_[256];                // noise sigma per grey level (read + shot noise)
  double phase_[2];
};

}  // namespace plslam::synth
