#include "plslam/synth/imu_synth.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "plslam/core/error.h"
#include "plslam/synth/texture.h"

namespace plslam::synth {

double parse_imu_noise(const std::string& text) {
  if (text == "none") return 0;
  if (text == "euroc") return 1;
  double f = -1;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), f);
  if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(f) || f < 0) {
    throw InputError("", "bad --imu-noise '" + text + "' (expected none, euroc or a factor >= 0)");
  }
  return f;
}

namespace {

// A standard normal draw (Box-Muller), so that noise is the same on every standard library.
double normal(Rng& rng) {
  const double u1 = std::max(rng.uniform(), 1e-300), u2 = rng.uniform();
  return std::sqrt(-2 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

Eigen::Vector3d normal3(Rng& rng) {
  const double x = normal(rng), y = normal(rng);
  return {x, y, normal(rng)};
}

}  // namespace

SyntheticImu::SyntheticImu(const Sequence& seq, const Eigen::Isometry3d& T_bc, const ImuSynthOptions& options,
                           std::uint64_t seed)
    : seq_(seq), T_bc_(T_bc), options_(options) {
  if (!(options.rate_hz >= 1 && options.rate_hz <= 100000)) throw InputError("", "--imu-rate must be in [1, 100000] Hz");
  if (!std::isfinite(options.time_offset) || std::abs(options.time_offset) > 0.5) {
    throw InputError("", "--imu-time-offset must be within +-0.5 s");
  }
  if (!(options.noise_scale >= 0) || !std::isfinite(options.noise_scale)) throw InputError("", "bad IMU noise factor");
  const double F = options.noise_scale, dt = 1 / options.rate_hz;
  Rng rng(seed * 0xD1B54A32D192ED03ULL ^ 0x1A0);
  if (F > 0) {
    // Biases of the size EuRoC's ground truth shows (gyro up to ~0.08 rad/s, accelerometer ~0.1 m/s^2).
    for (int a = 0; a < 3; ++a) bg0_(a) = F * rng.uniform(-0.03, 0.03);
    for (int a = 0; a < 3; ++a) ba0_(a) = F * rng.uniform(-0.1, 0.1);
  }
  const ImuNoise n = noise();
  const double last = seq.time(seq.size() - 1);
  // The IMU's own clock ticks at k / rate; sequence time = IMU time + offset.
  const long k0 = static_cast<long>(std::floor((-options.margin_s - options.time_offset) * options.rate_hz));
  const long k1 = static_cast<long>(std::ceil((last + options.margin_s - options.time_offset) * options.rate_hz));
  samples_.reserve(static_cast<std::size_t>(k1 - k0 + 1));
  Eigen::Vector3d bg = bg0_, ba = ba0_;
  for (long k = k0; k <= k1; ++k) {
    const double t_imu = static_cast<double>(k) * dt;
    ImuSample s = ideal(t_imu + options.time_offset);
    s.t = t_imu;
    if (F > 0) {
      s.gyro += bg + normal3(rng) * (F * n.gyro_noise_density / std::sqrt(dt));
      s.acc += ba + normal3(rng) * (F * n.acc_noise_density / std::sqrt(dt));
    }
    samples_.push_back(s);
    bg_.push_back(bg);
    ba_.push_back(ba);
    if (F > 0) {
      bg += normal3(rng) * (F * n.gyro_random_walk * std::sqrt(dt));
      ba += normal3(rng) * (F * n.acc_random_walk * std::sqrt(dt));
    }
  }
}

ImuNoise SyntheticImu::noise() const {
  ImuNoise n = kEurocAdis16448Noise;
  if (options_.noise_scale > 0) {
    n.gyro_noise_density *= options_.noise_scale;
    n.gyro_random_walk *= options_.noise_scale;
    n.acc_noise_density *= options_.noise_scale;
    n.acc_random_walk *= options_.noise_scale;
  }
  return n;
}

SyntheticImu::BodyMotion SyntheticImu::body_motion(double t) const {
  const CameraKinematics k = seq_.path().kinematics(t);
  const Eigen::Isometry3d T_cb = T_bc_.inverse();  // constant: differentiated through R_wc only
  return {k.T_wc * T_cb, k.R_dot * T_cb.linear(), k.velocity + k.R_dot * T_cb.translation(),
          k.acceleration + k.R_ddot * T_cb.translation()};
}

ImuSample SyntheticImu::ideal(double t) const {
  const BodyMotion b = body_motion(t);
  const Eigen::Matrix3d R_wb = b.T_wb.linear();
  const Eigen::Matrix3d W = R_wb.transpose() * b.R_dot;  // hat(omega_b), up to rounding
  ImuSample s;
  s.t = t;
  s.gyro = 0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
  s.acc = R_wb.transpose() * (b.acceleration + Eigen::Vector3d(0, 0, kGravity));
  return s;
}

ImuTrueState SyntheticImu::true_state(double t) const {
  const BodyMotion b = body_motion(t);
  ImuTrueState s;
  s.t = t;
  s.T_wb = b.T_wb;
  s.v_wb = b.velocity;
  // Biases between the samples around t (IMU clock t - offset).
  const double t_imu = t - options_.time_offset;
  const auto it = std::lower_bound(samples_.begin(), samples_.end(), t_imu,
                                   [](const ImuSample& a, double x) { return a.t < x; });
  const std::size_t j = std::clamp<std::size_t>(static_cast<std::size_t>(it - samples_.begin()), 1, samples_.size() - 1);
  const double a = std::clamp((t_imu - samples_[j - 1].t) / (samples_[j].t - samples_[j - 1].t), 0.0, 1.0);
  s.bg = (1 - a) * bg_[j - 1] + a * bg_[j];
  s.ba = (1 - a) * ba_[j - 1] + a * ba_[j];
  return s;
}

}  // namespace plslam::synth
