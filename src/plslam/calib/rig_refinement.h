#pragma once
// Joint refinement of a stereo rig from board views: both cameras' intrinsics and distortion, the
// pose between them and every view's board pose, by minimising all corners' reprojection errors
// (Ceres). OpenCV's stereoCalibrate does this for radial-tangential lenses, but its fisheye
// version needs every view to show the same corners (opencv/opencv#21748), which a partly seen
// ChArUco board near a fisheye's rim never does; one solver serves all models here.
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/geometry/lens_model.h"

namespace plslam::calib {

// The pixel of a camera-frame point under a lens model, for Ceres' automatic differentiation:
// intrinsics = fx, fy, cx, cy, then the model's four coefficients. False where undefined.
template <class T>
bool project_lens(geometry::LensModel model, const T* intrinsics, const T* X, T* uv);

struct BoardObservation {
  int corner = 0;      // index into the board's corners
  cv::Point2f pixel;
};

struct RigView {
  std::vector<BoardObservation> left, right;  // either may be empty
  Eigen::Isometry3d T_left_board = Eigen::Isometry3d::Identity();  // initial guess
};

// One corner's reprojection error after the solve (projected minus observed), for reports.
struct CornerError {
  int view = 0;  // index into the views
  cv::Point2f pixel, error;
};

struct RigRefinement {
  geometry::LensCamera left, right;
  std::vector<CornerError> left_errors, right_errors;
  Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
  double rms_px = 0;          // over every corner of both cameras
  int observations = 0;
  bool converged = false;
};

// `hold_distortion`: the coefficients stay as given (a pinhole keeps its zeros).
RigRefinement refine_rig(const geometry::LensCamera& left, const geometry::LensCamera& right,
                         const Eigen::Isometry3d& T_right_left, const std::vector<RigView>& views,
                         const std::vector<cv::Point3f>& corners, bool hold_distortion);

}  // namespace plslam::calib
