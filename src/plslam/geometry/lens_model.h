#pragma once
// Lens models of a raw (not yet rectified) camera, with the conventions of Kalibr, ASL/EuRoC
// sensor.yaml and OpenCV:
//   radial-tangential (OpenCV's plumb-bob with k3 = 0): x_d = x (1 + k1 r^2 + k2 r^4)
//     + 2 p1 x y + p2 (r^2 + 2 x^2), and alike for y, where (x, y) = (X/Z, Y/Z); a pinhole is
//     radial-tangential with all four coefficients zero;
//   equidistant (Kannala-Brandt, OpenCV's fisheye): theta = angle between the ray and the optical
//     axis, theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8), and the
//     pixel lies at radius theta_d (in focal units) along the ray's direction in the image.
// Pixels are then u = fx x_d + cx, v = fy y_d + cy.
#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace plslam::geometry {

enum class LensModel { kRadialTangential, kEquidistant };

// "radial-tangential" (also "radtan") or "equidistant" (also "fisheye"); nullopt otherwise.
std::optional<LensModel> parse_lens_model(const std::string& name);
const char* to_string(LensModel model);  // "radial-tangential" | "equidistant"

struct LensCamera {
  LensModel model = LensModel::kRadialTangential;
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 4> coeffs{};  // k1 k2 p1 p2 (radial-tangential) or k1 k2 k3 k4 (equidistant)

  // Pixel of a camera-frame ray (any length). Radial-tangential needs Z > 0; equidistant takes any
  // ray but the one straight behind. nullopt outside the model's domain.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& ray) const;
  // Unit ray through a pixel, by Newton's method on the distortion; nullopt where it does not
  // converge (outside the monotonic part of the distortion).
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const;

  // The largest angle from the optical axis, among the rays through the image's border pixels,
  // in radians; nullopt when a border pixel cannot be unprojected.
  std::optional<double> max_ray_angle() const;
};

}  // namespace plslam::geometry
