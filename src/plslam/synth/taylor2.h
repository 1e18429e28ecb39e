#pragma once
// A number that carries its first and second derivative with respect to one variable (time), so
// that the camera path written once as a function of t also gives its exact velocity, acceleration
// and angular velocity: the synthetic IMU's measurements, with no finite differences.
#include <cmath>

namespace plslam::synth {

struct Taylor2 {
  double v = 0;   // value
  double d = 0;   // first derivative
  double dd = 0;  // second derivative

  constexpr Taylor2() = default;
  constexpr Taylor2(double value) : v(value) {}  // NOLINT: a constant is a Taylor2 with zero derivatives
  constexpr Taylor2(double value, double d1, double d2) : v(value), d(d1), dd(d2) {}
  static constexpr Taylor2 variable(double t) { return {t, 1, 0}; }
};

inline Taylor2 operator-(const Taylor2& a) { return {-a.v, -a.d, -a.dd}; }
inline Taylor2 operator+(const Taylor2& a, const Taylor2& b) { return {a.v + b.v, a.d + b.d, a.dd + b.dd}; }
inline Taylor2 operator-(const Taylor2& a, const Taylor2& b) { return {a.v - b.v, a.d - b.d, a.dd - b.dd}; }
inline Taylor2 operator*(const Taylor2& a, const Taylor2& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd};
}
inline Taylor2 operator/(const Taylor2& a, const Taylor2& b) {
  const double q = a.v / b.v;
  const double q1 = (a.d - q * b.d) / b.v;
  return {q, q1, (a.dd - 2 * q1 * b.d - q * b.dd) / b.v};
}
inline Taylor2& operator+=(Taylor2& a, const Taylor2& b) { return a = a + b; }
inline Taylor2& operator-=(Taylor2& a, const Taylor2& b) { return a = a - b; }
inline Taylor2& operator*=(Taylor2& a, const Taylor2& b) { return a = a * b; }

inline Taylor2 sin(const Taylor2& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {s, c * a.d, -s * a.d * a.d + c * a.dd};
}
inline Taylor2 cos(const Taylor2& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {c, -s * a.d, -c * a.d * a.d - s * a.dd};
}
inline Taylor2 sqrt(const Taylor2& a) {
  const double r = std::sqrt(a.v);
  return {r, a.d / (2 * r), a.dd / (2 * r) - a.d * a.d / (4 * r * r * r)};
}
inline Taylor2 atan2(const Taylor2& y, const Taylor2& x) {
  const double den = x.v * x.v + y.v * y.v;
  const double num = x.v * y.d - y.v * x.d;                   // den * angle'
  const double num1 = x.v * y.dd - y.v * x.dd;                // num'
  const double den1 = 2 * (x.v * x.d + y.v * y.d);            // den'
  return {std::atan2(y.v, x.v), num / den, (num1 * den - num * den1) / (den * den)};
}

inline double value_of(double x) { return x; }
inline double value_of(const Taylor2& x) { return x.v; }

}  // namespace plslam::synth
