#include "plslam/geometry/stereo_rectification.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "plslam/core/error.h"

namespace plslam::geometry {
namespace {

cv::Mat camera_matrix(const LensCamera& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

constexpr double kEps = 1e-6;  // pixels: a border pixel mapped onto the border is inside

double degrees(double radians) { return radians * 180.0 / M_PI; }

// Angle of the ray through a pixel from the optical axis, in the plane of the given axis (0: x, 1: y).
double ray_angle(const LensCamera& c, const Eigen::Vector2d& pixel, int axis) {
  const auto ray = c.unproject(pixel);
  return ray ? std::atan2((*ray)[axis], ray->z()) : 0.0;
}

RectificationCoverage coverage_of(const LensCamera& raw, const Eigen::Matrix3d& R, const StereoCalibration& rect) {
  RectificationCoverage cov;
  const double w = raw.width - 1.0, h = raw.height - 1.0;
  cov.raw_hfov_deg = degrees(ray_angle(raw, {w, raw.cy}, 0) - ray_angle(raw, {0, raw.cy}, 0));
  cov.raw_vfov_deg = degrees(ray_angle(raw, {raw.cx, h}, 1) - ray_angle(raw, {raw.cx, 0}, 1));
  cov.rect_hfov_deg = degrees(std::atan((w - rect.cx) / rect.fx) + std::atan(rect.cx / rect.fx));
  cov.rect_vfov_deg = degrees(std::atan((h - rect.cy) / rect.fy) + std::atan(rect.cy / rect.fy));
  // A grid of about 200 x 200 pixels of the raw image, sent through the rectification.
  const int sx = std::max(1, raw.width / 200), sy = std::max(1, raw.height / 200);
  long kept = 0, all = 0;
  for (int y = 0; y < raw.height; y += sy) {
    for (int x = 0; x < raw.width; x += sx) {
      ++all;
      const auto ray = raw.unproject({x, y});
      if (!ray) continue;
      const Eigen::Vector3d r = R * *ray;
      if (!(r.z() > 1e-9)) continue;
      const double u = rect.fx * r.x() / r.z() + rect.cx, v = rect.fy * r.y() / r.z() + rect.cy;
      kept += u >= -kEps && v >= -kEps && u <= w + kEps && v <= h + kEps;
    }
  }
  cov.kept_share = all > 0 ? static_cast<double>(kept) / all : 0.0;
  // The same grid of the rectified image, traced back to the raw one.
  long blank = 0;
  all = 0;
  for (int y = 0; y < rect.height; y += sy) {
    for (int x = 0; x < rect.width; x += sx) {
      ++all;
      const Eigen::Vector3d r = R.transpose() * Eigen::Vector3d((x - rect.cx) / rect.fx, (y - rect.cy) / rect.fy, 1.0);
      const auto p = raw.project(r);
      blank += !p || p->x() < -kEps || p->y() < -kEps || p->x() > w + kEps || p->y() > h + kEps;
    }
  }
  cov.blank_share = all > 0 ? static_cast<double>(blank) / all : 0.0;
  return cov;
}

}  // namespace

StereoRectification rectify_stereo(const RawStereoRig& rig, double balance, const std::string& source) {
  if (!(balance >= 0 && balance <= 1)) {
    throw InputError(source, fmt::format("rectification balance must be in [0, 1], got {}", balance));
  }
  const LensCamera& c0 = rig.left;
  const LensCamera& c1 = rig.right;
  if (c0.model != c1.model) {
    throw InputError(source, fmt::format("the cameras' lens models differ ({} and {}): one rig has one model",
                                         to_string(c0.model), to_string(c1.model)));
  }
  // Two cameras at one place give no depth (stereoRectify would assert); say so in plain words.
  const double baseline = rig.T_right_left.translation().norm();
  if (!(baseline > 1e-6)) {
    throw InputError(source, fmt::format("baseline must be positive, got {} m: both cameras are at one place", baseline));
  }
  cv::Mat R, T;
  cv::eigen2cv(Eigen::Matrix3d(rig.T_right_left.rotation()), R);
  cv::eigen2cv(Eigen::Vector3d(rig.T_right_left.translation()), T);
  const cv::Size size(c0.width, c0.height);
  const cv::Mat K0 = camera_matrix(c0), K1 = camera_matrix(c1);
  const cv::Mat D0(4, 1, CV_64F, const_cast<double*>(c0.coeffs.data()));
  const cv::Mat D1(4, 1, CV_64F, const_cast<double*>(c1.coeffs.data()));
  cv::Mat R1, R2, P1, P2, Q;
  StereoRectification out;
  if (c0.model == LensModel::kEquidistant) {
    cv::fisheye::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, size, balance);
    cv::fisheye::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_16SC2, out.map_left[0], out.map_left[1]);
    cv::fisheye::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_16SC2, out.map_right[0], out.map_right[1]);
  } else {
    // alpha = balance: 0 keeps only valid pixels, so no black borders produce spurious edges and corners.
    cv::stereoRectify(K0, D0, K1, D1, size, R, T, R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, balance, size);
    cv::initUndistortRectifyMap(K0, D0, R1, P1, size, CV_16SC2, out.map_left[0], out.map_left[1]);
    cv::initUndistortRectifyMap(K1, D1, R2, P2, size, CV_16SC2, out.map_right[0], out.map_right[1]);
  }
  StereoCalibration& rect = out.calibration;
  rect.width = c0.width;
  rect.height = c0.height;
  rect.fx = P1.at<double>(0, 0);
  rect.fy = P1.at<double>(1, 1);
  rect.cx = P1.at<double>(0, 2);
  rect.cy = P1.at<double>(1, 2);
  rect.baseline = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  if (!(rect.baseline > 0)) {
    throw InputError(source, fmt::format("baseline must be positive, got {} m after rectification: the right camera "
                                         "must sit to the right of the left one", rect.baseline));
  }
  if (!(rect.fx > 0 && rect.fy > 0)) {
    throw InputError(source, fmt::format("rectification gives focal lengths {} and {}: the rig cannot be rectified "
                                         "(cameras facing apart?)", rect.fx, rect.fy));
  }
  cv::cv2eigen(R1, out.R_rect_left);
  cv::cv2eigen(R2, out.R_rect_right);
  out.coverage = coverage_of(c0, out.R_rect_left, rect);
  return out;
}

}  // namespace plslam::geometry
