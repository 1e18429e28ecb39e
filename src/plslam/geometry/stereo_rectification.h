#pragma once
// Rectification of a raw stereo rig (two lens cameras and the pose between them) into the ideal
// pinhole pair the rest of the system works on: rows aligned, equal intrinsics, the right camera
// at +baseline along x. OpenCV computes it: cv::stereoRectify for radial-tangential lenses,
// cv::fisheye::stereoRectify for equidistant ones. A fisheye cannot be rectified whole (a pinhole
// holds less than 180 degrees, and needs ever more pixels towards it), so `balance` chooses the
// rectified field of view: 0 keeps only pixels both raw images see (no black border), 1 keeps the
// whole raw field of view along the borders' middles (OpenCV's balance; for radial-tangential
// lenses its alpha).
#include <array>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/core/types.h"
#include "plslam/geometry/lens_model.h"

namespace plslam::geometry {

struct RawStereoRig {
  LensCamera left, right;  // of the same image size
  // The left camera in the right one's frame: p_right = T_right_left * p_left.
  Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
};

// What rectification keeps of the raw view, for `plslam info`.
struct RectificationCoverage {
  double raw_hfov_deg = 0, raw_vfov_deg = 0;    // the raw left image, through its centre lines
  double rect_hfov_deg = 0, rect_vfov_deg = 0;  // the rectified left image
  double kept_share = 0;                        // of the raw left image's pixels, in the rectified one
  double blank_share = 0;  // of the rectified left image, with no raw pixel behind it (black border)
};

struct StereoRectification {
  StereoCalibration calibration;  // the rectified pinhole pair, of the raw image size
  Eigen::Matrix3d R_rect_left = Eigen::Matrix3d::Identity();   // raw left camera frame -> rectified
  Eigen::Matrix3d R_rect_right = Eigen::Matrix3d::Identity();  // raw right camera frame -> rectified
  std::array<cv::Mat, 2> map_left, map_right;  // for cv::remap (CV_16SC2 + CV_16UC1)
  RectificationCoverage coverage;
};

// Throws InputError naming `source` when the rig cannot be rectified: two cameras at one place, a
// balance outside [0, 1], or a result with the right camera not to the right of the left one.
StereoRectification rectify_stereo(const RawStereoRig& rig, double balance, const std::string& source);

}  // namespace plslam::geometry
