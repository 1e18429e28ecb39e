#pragma once
// Rectified stereo pinhole camera. A camera-frame point X = (x, y, z) projects to the left
// image at (u_l, v) = (fx x/z + cx, fy y/z + cy) and to the right image at
// (u_r, v) with u_r = u_l - bf/z (the right camera sits at +baseline along x).
#include <optional>

#include <Eigen/Core>

#include "plslam/core/types.h"

namespace plslam::geometry {

class StereoCamera {
 public:
  StereoCamera() = default;
  StereoCamera(double fx, double fy, double cx, double cy, double bf, int width, int height);
  explicit StereoCamera(const StereoCalibration& calib);

  // Left-image pixel of a camera-frame point (z must be positive).
  Eigen::Vector2d project(const Eigen::Vector3d& Xc) const {
    const double iz = 1.0 / Xc.z();
    return {fx_ * Xc.x() * iz + cx_, fy_ * Xc.y() * iz + cy_};
  }
  // (u_l, v, u_r).
  Eigen::Vector3d project_stereo(const Eigen::Vector3d& Xc) const {
    const double iz = 1.0 / Xc.z();
    const double ul = fx_ * Xc.x() * iz + cx_;
    return {ul, fy_ * Xc.y() * iz + cy_, ul - bf_ * iz};
  }
  // Point at the given depth along the left-image ray through uv.
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv, double depth) const {
    return {(uv.x() - cx_) / fx_ * depth, (uv.y() - cy_) / fy_ * depth, depth};
  }
  // Normalised ray (z = 1) through a left-image pixel.
  Eigen::Vector3d ray(const Eigen::Vector2d& uv) const {
    return {(uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_, 1.0};
  }
  // Depth from the disparity u_l - u_r; nullopt when the disparity is not positive.
  std::optional<Eigen::Vector3d> unproject_stereo(const Eigen::Vector3d& obs) const;

  bool in_image(const Eigen::Vector2d& uv, double margin = 0.0) const {
    return uv.x() >= margin && uv.y() >= margin && uv.x() < width_ - margin &&
           uv.y() < height_ - margin;
  }

  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  double bf() const { return bf_; }
  double baseline() const { return bf_ / fx_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  double fx_ = 1.0, fy_ = 1.0, cx_ = 0.0, cy_ = 0.0, bf_ = 0.0;
  int width_ = 0, height_ = 0;
};

// Image line a*u + b*v + c = 0 through two pixels, scaled so that (a, b) has unit norm: l.dot(p, 1)
// is then the signed pixel distance of p to the line. The points must be distinct.
Eigen::Vector3d line_through(const Eigen::Vector2d& p, const Eigen::Vector2d& q);

}  // namespace plslam::geometry
