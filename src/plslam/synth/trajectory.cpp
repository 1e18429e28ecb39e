#include "plslam/synth/trajectory.h"

#include <algorithm>
#include <cmath>

#include "plslam/core/error.h"
#include "plslam/synth/taylor2.h"

namespace plslam::synth {

namespace {
constexpr double kPi = 3.141592653589793;
constexpr double kTwoPi = 2 * kPi;

template <class S>
void rotation_from_angles(const S& yaw, const S& pitch, const S& roll, S (&R)[3][3]) {
  using std::cos;
  using std::sin;
  const S f[3] = {cos(yaw) * cos(pitch), sin(yaw) * cos(pitch), sin(pitch)};
  const S right0[3] = {sin(yaw), -cos(yaw), S(0.0)};
  // down0 = f x right0
  const S down0[3] = {f[1] * right0[2] - f[2] * right0[1], f[2] * right0[0] - f[0] * right0[2],
                      f[0] * right0[1] - f[1] * right0[0]};
  const S cr = cos(roll), sr = sin(roll);
  const S right[3] = {cr * right0[0] + sr * down0[0], cr * right0[1] + sr * down0[1], cr * right0[2] + sr * down0[2]};
  const S down[3] = {f[1] * right[2] - f[2] * right[1], f[2] * right[0] - f[0] * right[2], f[0] * right[1] - f[1] * right[0]};
  for (int r = 0; r < 3; ++r) {
    R[r][0] = right[r];
    R[r][1] = down[r];
    R[r][2] = f[r];
  }
}

// One segment of a uniform cubic B-spline at local parameter tau in [0, 1).
template <class S>
S bspline(const S& tau, double p0, double p1, double p2, double p3) {
  const S t2 = tau * tau, t3 = t2 * tau, w = S(1.0) - tau;
  return (w * w * w * p0 + (S(3.0) * t3 - S(6.0) * t2 + S(4.0)) * p1 +
          (S(-3.0) * t3 + S(3.0) * t2 + S(3.0) * tau + S(1.0)) * p2 + t3 * p3) * S(1.0 / 6.0);
}

// x - floor(x) with x's derivatives, and floor(x) as an index.
template <class S>
S fraction(const S& x, long& index) {
  const double f = std::floor(value_of(x));
  index = static_cast<long>(f);
  return x - S(f);
}

std::size_t wrap(long i, std::size_t n) {
  const long m = static_cast<long>(n);
  return static_cast<std::size_t>(((i % m) + m) % m);
}

// A look aside and back once per period: sin^4 over `duration` seconds (C3 where it starts and
// ends), zero for the rest of the period, alternately to either side. Its peak rate is about
// 4.08 * amplitude / duration.
template <class S>
S quick_turn(const S& t, double period, double duration, double phase, double amplitude) {
  long k = 0;
  const S into = fraction((t + S(phase)) * S(1.0 / period), k) * S(period);
  if (value_of(into) >= duration) return S(0.0);
  using std::sin;
  const S b = sin(into * S(kPi / duration)), b2 = b * b;
  return b2 * b2 * S(k % 2 == 0 ? amplitude : -amplitude);
}

template <class S>
S wave(const S& t, double amplitude, double hz, double phase) {
  using std::sin;
  return S(amplitude) * sin(t * S(kTwoPi * hz) + S(phase));
}

}  // namespace

const char* to_string(MotionProfile m) {
  switch (m) {
    case MotionProfile::kWalk: return "walk";
    case MotionProfile::kHandheld: return "handheld";
    case MotionProfile::kDrone: return "drone";
  }
  return "?";
}

MotionProfile parse_motion_profile(const std::string& name) {
  if (name == "walk") return MotionProfile::kWalk;
  if (name == "handheld") return MotionProfile::kHandheld;
  if (name == "drone") return MotionProfile::kDrone;
  throw InputError("", "unknown motion '" + name + "' (expected walk, handheld or drone)");
}

Eigen::Matrix3d camera_rotation(double yaw, double pitch, double roll) {
  double R[3][3];
  rotation_from_angles(yaw, pitch, roll, R);
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) M(r, c) = R[r][c];
  }
  return M;
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

CameraPath::CameraPath(const Scene& scene, double speed, std::uint64_t seed, std::uint64_t path_seed,
                       MotionProfile motion)
    : control_(scene.path), speed_(speed), height_(scene.camera_height), vehicle_(scene.vehicle),
      look_around_(scene.look_around), variation_(path_variation(path_seed, scene.vehicle)), motion_(motion) {
  const std::size_t n = control_.size();
  if (n < 4) throw InputError("", "a scene path needs at least 4 control points");
  // Arc length against the spline parameter, from fine chords (their error is ~1e-7 relative).
  constexpr int kPerSegment = 400;
  std::vector<double> table(n * kPerSegment + 1, 0.0);
  double prev[2] = {0, 0};
  for (std::size_t k = 0; k < table.size(); ++k) {
    double xy[2];
    const double u = static_cast<double>(k) / kPerSegment;
    const std::size_t i = std::min(k / kPerSegment, n - 1);
    const double tau = u - static_cast<double>(i);
    for (int c = 0; c < 2; ++c) {
      xy[c] = bspline(tau, control_[wrap(static_cast<long>(i) - 1, n)][c], control_[i][c], control_[wrap(static_cast<long>(i) + 1, n)][c],
                      control_[wrap(static_cast<long>(i) + 2, n)][c]);
    }
    if (k > 0) table[k] = table[k - 1] + std::hypot(xy[0] - prev[0], xy[1] - prev[1]);
    prev[0] = xy[0];
    prev[1] = xy[1];
  }
  length_ = table.back();
  // The inverse, u(s), sampled at uniform knots and kept as offsets from the mean rate n / length.
  const std::size_t knots = 16 * n;
  u_offset_.resize(knots);
  for (std::size_t j = 0; j < knots; ++j) {
    const double s = length_ * static_cast<double>(j) / static_cast<double>(knots);
    const auto it = std::upper_bound(table.begin(), table.end(), s);
    const std::size_t k = std::clamp<std::size_t>(static_cast<std::size_t>(it - table.begin()), 1, table.size() - 1);
    const double a = (s - table[k - 1]) / std::max(1e-300, table[k] - table[k - 1]);
    const double u = (static_cast<double>(k - 1) + a) / kPerSegment;
    u_offset_[j] = u - s * static_cast<double>(n) / length_;
  }
  Rng rng(seed ^ 0x7A11 ^ (path_seed * 0x100000001B3ULL));
  for (double& p : phase_) p = rng.uniform(0, kTwoPi);
  Rng motion_rng(seed * 0x9E3779B97F4A7C15ULL ^ 0x5AC3 ^ (path_seed * 0x100000001B3ULL));
  for (double& p : motion_phase_) p = motion_rng.uniform(0, kTwoPi);
}

template <class S>
void CameraPath::position(const S& s_in, S (&xy)[2]) const {
  const std::size_t n = control_.size(), knots = u_offset_.size();
  long wraps = 0;
  const S s = fraction(s_in * S(1.0 / length_), wraps) * S(length_);  // in [0, length)
  long j = 0;
  const S tau = fraction(s * S(static_cast<double>(knots) / length_), j);
  const S u_raw = s * S(static_cast<double>(n) / length_) +
                  bspline(tau, u_offset_[wrap(j - 1, knots)], u_offset_[wrap(j, knots)], u_offset_[wrap(j + 1, knots)],
                          u_offset_[wrap(j + 2, knots)]);
  long i = 0;
  const S v = fraction(u_raw, i);
  for (int c = 0; c < 2; ++c) {
    xy[c] = bspline(v, control_[wrap(i - 1, n)][c], control_[wrap(i, n)][c], control_[wrap(i + 1, n)][c],
                    control_[wrap(i + 2, n)][c]);
  }
}

template <class S>
S CameraPath::heading(const S& s, double window) const {
  S a[2], b[2];
  position(s + S(window), a);
  position(s - S(window), b);
  using std::atan2;
  return atan2(a[1] - b[1], a[0] - b[0]);
}

template <class S>
void CameraPath::evaluate(const S& t, S (&R)[3][3], S (&p)[3]) const {
  using std::cos;
  using std::sin;
  const double direction = variation_.reverse ? -1.0 : 1.0;
  const S s = S(variation_.start * length()) + S(direction * speed_) * t;
  const double travel = variation_.reverse ? kPi : 0.0;  // heading() follows the loop's own way
  S xy[2];
  position(s, xy);
  const S h = heading(s, vehicle_ ? 1.5 : 0.4) + S(travel);
  const S left[2] = {-sin(h), cos(h)};
  S side = S(variation_.lateral);  // metres to the left of the path
  S yaw, pitch, roll, z;
  if (vehicle_) {
    yaw = h;
    pitch = wave(t, 0.006, 1 / 2.3, phase_[0]);
    roll = wave(t, 0.004, 1 / 3.1, phase_[1]);
    z = S(height_) + wave(t, 0.01, 1 / 1.7, phase_[2]);
  } else {
    // Walking: lateral sway at the stride rate, bobbing at twice it, slow looking around.
    side += wave(t, 0.03, 0.9, phase_[0]);
    z = S(height_) + wave(t, 0.02, 1.8, phase_[1]);
    yaw = h + wave(t, look_around_, 1 / 6.1, phase_[2]);
    pitch = S(-0.06) + wave(t, 0.05, 1 / 4.3, phase_[3]);
    roll = wave(t, 0.03, 1 / 3.7, phase_[4]);
  }
  const double* ph = motion_phase_;
  S shake[3] = {S(0.0), S(0.0), S(0.0)};
  if (motion_ == MotionProfile::kHandheld) {
    // Looks aside and back every 5 s (1.9 rad/s, 3 with the path's own turns and the shake), and
    // hand tremor: +-2 mm and +-0.5 degree at 5-12 Hz.
    yaw += quick_turn(t, 5.0, 1.3, 5.0 * ph[0] / kTwoPi, 0.6);
    pitch += wave(t, 0.005, 6.3, ph[1]) + wave(t, 0.003, 9.7, ph[2]);
    roll += wave(t, 0.004, 7.1, ph[3]);
    for (int a = 0; a < 3; ++a) {
      shake[a] = wave(t, 0.0009, 5.3 + 0.4 * a, ph[4 + a]) + wave(t, 0.0006, 8.9 - 0.3 * a, ph[7 + a]) +
                 wave(t, 0.0003, 12.1 + 0.5 * a, ph[10 + (a % 2)]);
    }
  } else if (motion_ == MotionProfile::kDrone) {
    // Yaw turns every 6 s (2.4 rad/s, 3 with the path's own turns); swoops sideways (+-0.1 m at
    // 1 Hz) and up and down (+-0.04 m at 1.6 Hz) with the roll a multicopter needs to accelerate
    // sideways; rotor vibration.
    yaw += quick_turn(t, 6.0, 1.5, 6.0 * ph[0] / kTwoPi, 0.9);
    const double swoop = 0.1, swoop_hz = 1.0;
    side += wave(t, swoop, swoop_hz, ph[1]);
    const double side_acc = swoop * (kTwoPi * swoop_hz) * (kTwoPi * swoop_hz);
    roll += wave(t, 0.5 * side_acc / 9.81, swoop_hz, ph[1]);  // accelerating left (side'' > 0) rolls left
    z += wave(t, 0.04, 1.6, ph[2]);
    pitch += wave(t, 0.003, 14.0, ph[3]);
    roll += wave(t, 0.002, 17.0, ph[4]);
    for (int a = 0; a < 3; ++a) shake[a] = wave(t, 0.0002, 16.0 + 1.3 * a, ph[5 + a]);
  }
  p[0] = xy[0] + left[0] * side + shake[0];
  p[1] = xy[1] + left[1] * side + shake[1];
  p[2] = z + S(variation_.height) + shake[2];
  rotation_from_angles(yaw, pitch, roll, R);
}

Eigen::Isometry3d CameraPath::pose(double t) const {
  double R[3][3], p[3];
  evaluate(t, R, p);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R[r][c];
    T.translation()(r) = p[r];
  }
  return T;
}

CameraKinematics CameraPath::kinematics(double t) const {
  Taylor2 R[3][3], p[3];
  evaluate(Taylor2::variable(t), R, p);
  CameraKinematics k;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      k.T_wc.linear()(r, c) = R[r][c].v;
      k.R_dot(r, c) = R[r][c].d;
      k.R_ddot(r, c) = R[r][c].dd;
    }
    k.T_wc.translation()(r) = p[r].v;
    k.velocity(r) = p[r].d;
    k.acceleration(r) = p[r].dd;
  }
  return k;
}

}  // namespace plslam::synth
