#include "plslam/synth/trajectory.h"

#include <algorithm>
#include <cmath>

namespace plslam::synth {

namespace {
constexpr double kTwoPi = 6.283185307179586;
}

Eigen::Matrix3d camera_rotation(double yaw, double pitch, double roll) {
  const Eigen::Vector3d f(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch));
  const Eigen::Vector3d right0(std::sin(yaw), -std::cos(yaw), 0);
  const Eigen::Vector3d down0 = f.cross(right0);
  const Eigen::Vector3d right = std::cos(roll) * right0 + std::sin(roll) * down0;
  const Eigen::Vector3d down = f.cross(right);
  Eigen::Matrix3d R;
  R.col(0) = right;
  R.col(1) = down;
  R.col(2) = f;
  return R;
}

PathVariation path_variation(std::uint64_t path_seed, bool vehicle) {
  if (path_seed == 0) return {};
  Rng rng(path_seed * 0x9E3779B97F4A7C15ULL ^ 0x5EED);
  PathVariation v;
  v.start = rng.uniform(0, 1);
  v.reverse = rng.uniform() < 0.5;
  v.lateral = rng.uniform(-1, 1) * (vehicle ? 0.5 : 0.25);
  v.height = rng.uniform(-1, 1) * (vehicle ? 0.05 : 0.1);
  return v;
}

CameraPath::CameraPath(const Scene& scene, double speed, std::uint64_t seed, std::uint64_t path_seed)
    : speed_(speed), height_(scene.camera_height), vehicle_(scene.vehicle), look_around_(scene.look_around),
      variation_(path_variation(path_seed, scene.vehicle)) {
  const auto& P = scene.path;
  const int n = static_cast<int>(P.size());
  constexpr int kPerSegment = 200;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p0 = P[(i + n - 1) % n];
    const Eigen::Vector2d& p1 = P[i];
    const Eigen::Vector2d& p2 = P[(i + 1) % n];
    const Eigen::Vector2d& p3 = P[(i + 2) % n];
    for (int k = 0; k < kPerSegment; ++k) {
      const double t = double(k) / kPerSegment, t2 = t * t, t3 = t2 * t;
      samples_.push_back(((1 - t) * (1 - t) * (1 - t) * p0 + (3 * t3 - 6 * t2 + 4) * p1 +
                          (-3 * t3 + 3 * t2 + 3 * t + 1) * p2 + t3 * p3) / 6.0);
    }
  }
  samples_.push_back(samples_.front());  // close the loop
  cumulative_.resize(samples_.size());
  cumulative_[0] = 0;
  for (std::size_t i = 1; i < samples_.size(); ++i)
    cumulative_[i] = cumulative_[i - 1] + (samples_[i] - samples_[i - 1]).norm();
  Rng rng(seed ^ 0x7A11 ^ (path_seed * 0x100000001B3ULL));
  for (double& p : phase_) p = rng.uniform(0, kTwoPi);
}

Eigen::Vector2d CameraPath::position(double s) const {
  const double L = length();
  s = std::fmod(s, L);
  if (s < 0) s += L;
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - cumulative_.begin()), 1, cumulative_.size() - 1);
  const double seg = cumulative_[i] - cumulative_[i - 1];
  const double a = seg > 0 ? (s - cumulative_[i - 1]) / seg : 0;
  return samples_[i - 1] + a * (samples_[i] - samples_[i - 1]);
}

double CameraPath::heading(double s, double window) const {
  const Eigen::Vector2d d = position(s + window) - position(s - window);
  return std::atan2(d.y(), d.x());
}

Eigen::Isometry3d CameraPath::pose(double t) const {
  const double direction = variation_.reverse ? -1.0 : 1.0;
  const double s = variation_.start * length() + direction * speed_ * t;
  const double travel = variation_.reverse ? std::acos(-1.0) : 0.0;  // heading() follows the loop's own way
  Eigen::Vector2d p = position(s);
  if (variation_.lateral != 0) {
    const double h = heading(s, vehicle_ ? 1.5 : 0.4) + travel;
    p += Eigen::Vector2d(-std::sin(h), std::cos(h)) * variation_.lateral;
  }
  double yaw, pitch, roll, z;
  if (vehicle_) {
    yaw = heading(s, 1.5) + travel;
    pitch = 0.006 * std::sin(kTwoPi * t / 2.3 + phase_[0]);
    roll = 0.004 * std::sin(kTwoPi * t / 3.1 + phase_[1]);
    z = height_ + 0.01 * std::sin(kTwoPi * t / 1.7 + phase_[2]);
  } else {
    // Walking: lateral sway at the stride rate, bobbing at twice it, slow looking around.
    const double h = heading(s, 0.4) + travel;
    const Eigen::Vector2d lateral(-std::sin(h), std::cos(h));
    p += lateral * (0.03 * std::sin(kTwoPi * 0.9 * t + phase_[0]));
    z = height_ + 0.02 * std::sin(kTwoPi * 1.8 * t + phase_[1]);
    yaw = h + look_around_ * std::sin(kTwoPi * t / 6.1 + phase_[2]);
    pitch = -0.06 + 0.05 * std::sin(kTwoPi * t / 4.3 + phase_[3]);
    roll = 0.03 * std::sin(kTwoPi * t / 3.7 + phase_[4]);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = camera_rotation(yaw, pitch, roll);
  T.translation() = Eigen::Vector3d(p.x(), p.y(), z + variation_.height);
  return T;
}

}  // namespace plslam::synth
