#include "plslam/geometry/lens_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace plslam::geometry {
namespace {

constexpr int kNewtonIterations = 30;
constexpr double kTolerance = 1e-13;  // in normalised image units: far below a thousandth of a pixel

// Radial-tangential distortion of a normalised point and its Jacobian.
Eigen::Vector2d radtan(const std::array<double, 4>& c, const Eigen::Vector2d& p, Eigen::Matrix2d* J) {
  const double x = p.x(), y = p.y(), r2 = x * x + y * y;
  const double radial = 1 + c[0] * r2 + c[1] * r2 * r2;
  const Eigen::Vector2d d(x * radial + 2 * c[2] * x * y + c[3] * (r2 + 2 * x * x),
                          y * radial + c[2] * (r2 + 2 * y * y) + 2 * c[3] * x * y);
  if (J) {
    const double dradial = 2 * c[0] + 4 * c[1] * r2;  // d(radial)/d(r2) * 2
    (*J)(0, 0) = radial + x * dradial * x + 2 * c[2] * y + 6 * c[3] * x;
    (*J)(0, 1) = x * dradial * y + 2 * c[2] * x + 2 * c[3] * y;
    (*J)(1, 0) = y * dradial * x + 2 * c[2] * x + 2 * c[3] * y;
    (*J)(1, 1) = radial + y * dradial * y + 6 * c[2] * y + 2 * c[3] * x;
  }
  return d;
}

// theta_d(theta) of the equidistant model and its derivative.
double kb_theta_d(const std::array<double, 4>& k, double t, double* dt) {
  const double t2 = t * t;
  const double poly = 1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
  if (dt) *dt = 1 + t2 * (3 * k[0] + t2 * (5 * k[1] + t2 * (7 * k[2] + t2 * 9 * k[3])));
  return t * poly;
}

}  // namespace

std::optional<LensModel> parse_lens_model(const std::string& name) {
  if (name == "radial-tangential" || name == "radtan") return LensModel::kRadialTangential;
  if (name == "equidistant" || name == "fisheye") return LensModel::kEquidistant;
  return std::nullopt;
}

const char* to_string(LensModel model) {
  return model == LensModel::kEquidistant ? "equidistant" : "radial-tangential";
}

std::optional<Eigen::Vector2d> LensCamera::project(const Eigen::Vector3d& ray) const {
  Eigen::Vector2d d;
  if (model == LensModel::kRadialTangential) {
    if (!(ray.z() > 0)) return std::nullopt;
    d = radtan(coeffs, ray.head<2>() / ray.z(), nullptr);
  } else {
    const double rho = ray.head<2>().norm();
    if (rho == 0) {
      if (!(ray.z() > 0)) return std::nullopt;
      d.setZero();
    } else {
      const double theta = std::atan2(rho, ray.z());
      if (theta > M_PI - 1e-9) return std::nullopt;
      d = ray.head<2>() * (kb_theta_d(coeffs, theta, nullptr) / rho);
    }
  }
  return Eigen::Vector2d(fx * d.x() + cx, fy * d.y() + cy);
}

std::optional<Eigen::Vector3d> LensCamera::unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  if (model == LensModel::kRadialTangential) {
    Eigen::Vector2d p = d;
    for (int it = 0; it < kNewtonIterations; ++it) {
      Eigen::Matrix2d J;
      const Eigen::Vector2d residual = radtan(coeffs, p, &J) - d;
      // A solution where the distortion has folded over (det J <= 0) is an image of the wrong ray.
      if (!(J.determinant() > 1e-9)) return std::nullopt;
      if (residual.norm() < kTolerance) return Eigen::Vector3d(p.x(), p.y(), 1.0).normalized();
      p -= J.inverse() * residual;
      if (!p.allFinite()) return std::nullopt;
    }
    return std::nullopt;
  }
  const double theta_d = d.norm();
  if (theta_d == 0) return Eigen::Vector3d::UnitZ();
  double theta = theta_d;
  for (int it = 0; it < kNewtonIterations; ++it) {
    double slope = 0;
    const double residual = kb_theta_d(coeffs, theta, &slope) - theta_d;
    if (std::abs(residual) < kTolerance) {
      if (!(theta > 0 && theta < M_PI)) return std::nullopt;
      const double s = std::sin(theta) / theta_d;
      return Eigen::Vector3d(d.x() * s, d.y() * s, std::cos(theta));
    }
    if (!(slope > 1e-9)) return std::nullopt;  // theta_d is no longer increasing
    theta -= residual / slope;
    if (!std::isfinite(theta)) return std::nullopt;
  }
  return std::nullopt;
}

std::optional<double> LensCamera::max_ray_angle() const {
  double worst = 0;
  const int steps = 64;
  for (int k = 0; k <= steps; ++k) {
    const double a = static_cast<double>(k) / steps;
    const double x = a * (width - 1), y = a * (height - 1);
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(x, 0), Eigen::Vector2d(x, height - 1.0),
                                     Eigen::Vector2d(0, y), Eigen::Vector2d(width - 1.0, y)}) {
      const auto r = unproject(p);
      if (!r) return std::nullopt;
      worst = std::max(worst, std::acos(std::clamp(r->z(), -1.0, 1.0)));
    }
  }
  return worst;
}

}  // namespace plslam::geometry
