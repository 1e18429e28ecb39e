#include "plslam/synth/sensor.h"

#include <algorithm>
#include <cmath>

#include "plslam/synth/texture.h"

namespace plslam::synth {

SensorModel::SensorModel(int width, int height, std::uint64_t seed) : width_(width), height_(height) {
  vignette_.resize(static_cast<std::size_t>(width) * height);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const double r2max = cx * cx + cy * cy;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2max;
      vignette_[static_cast<std::size_t>(y) * width + x] = static_cast<float>(1.0 - 0.22 * r2);
    }
  Rng rng(seed ^ 0x5E5502);
  gauss_.resize(4096);
  for (std::size_t i = 0; i < gauss_.size(); i += 2) {  // Box-Muller
    const double u1 = std::max(rng.uniform(), 1e-12), u2 = rng.uniform();
    const double r = std::sqrt(-2 * std::log(u1));
    gauss_[i] = static_cast<float>(r * std::cos(6.283185307179586 * u2));
    gauss_[i + 1] = static_cast<float>(r * std::sin(6.283185307179586 * u2));
  }
  for (int i = 0; i < 256; ++i) sigma_[i] = static_cast<float>(std::sqrt(1.0 + 0.012 * i));
  phase_[0] = rng.uniform(0, 6.283185307179586);
  phase_[1] = rng.uniform(0, 6.283185307179586);
}

double SensorModel::exposure(double t) const {
  return 1.0 + 0.2 * (0.6 * std::sin(6.283185307179586 * t / 7.3 + phase_[0]) +
                      0.4 * std::sin(6.283185307179586 * t / 3.1 + phase_[1]));
}

void SensorModel::expose(const cv::Mat& radiance, double exposure, std::uint64_t noise_seed, cv::Mat& out) const {
  CV_Assert(radiance.type() == CV_32F && radiance.cols == width_ && radiance.rows == height_);
  out.create(height_, width_, CV_8U);
  const float gain = static_cast<float>(kGain * exposure);
  // xorshift32 per image: cheap and fully determined by the seed.
  std::uint32_t state = static_cast<std::uint32_t>(Rng(noise_seed).next() | 1u);
  for (int y = 0; y < height_; ++y) {
    const float* r = radiance.ptr<float>(y);
    const float* v = &vignette_[static_cast<std::size_t>(y) * width_];
    std::uint8_t* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < width_; ++x) {
      const float signal = std::min(255.0f, r[x] * gain * v[x]);
      state ^= state << 13;
      state ^= state >> 17;
      state ^= state << 5;
      const float noisy = signal + sigma_[static_cast<int>(signal)] * gauss_[state & 4095u];
      o[x] = static_cast<std::uint8_t>(std::clamp(noisy + 0.5f, 0.0f, 255.0f));
    }
  }
}

}  // namespace plslam::synth
