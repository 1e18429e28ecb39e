#pragma once
// Stereo calibration from board views: OpenCV's calibrateCamera / fisheye::calibrate for each
// camera, then stereoCalibrate / fisheye::stereoCalibrate for both together, with the views chosen
// for coverage of the image and outlier views rejected by their reprojection error.
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/calib/board.h"
#include "plslam/geometry/lens_model.h"

namespace plslam::calib {

// pinhole: radial-tangential with all coefficients held at zero.
enum class CalibrationModel { kPinhole, kRadialTangential, kEquidistant };
CalibrationModel parse_calibration_model(const std::string& name);  // pinhole|radtan|equidistant; InputError else
const char* to_string(CalibrationModel model);

struct CalibrationOptions {
  CalibrationModel model = CalibrationModel::kRadialTangential;
  int max_views = 40;        // views kept for the solve, chosen for coverage
  int min_corners = 12;      // a view with fewer corners (in either camera, for stereo) is left out
  double outlier_factor = 3.0;  // a view whose RMS error exceeds this times the median, and
  double outlier_floor_px = 0.5;  // this, is rejected and the solve repeated
  int coverage_cells_x = 8, coverage_cells_y = 6;  // the grid the coverage report and selection use
};

struct StereoView {
  int frame = 0;
  BoardDetection left, right;
};

struct CameraReport {
  geometry::LensCamera lens;
  double rms_px = 0;                 // over the views it was solved on, after the joint solve
  std::vector<int> views;            // frames used
  std::vector<double> view_rms_px;   // per used view
  std::vector<int> rejected;         // frames rejected as outliers
  double covered_share = 0;          // of the coverage grid's cells with a corner
  double max_tilt_deg = 0;           // the most tilted board among the views
  // Every corner of the kept views after the joint solve: frame, pixel, projected minus observed.
  struct Corner {
    int frame = 0;
    cv::Point2f pixel, error;
  };
  std::vector<Corner> corners;
};

struct StereoCalibrationResult {
  CameraReport left, right;
  Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();  // p_right = T * p_left
  double stereo_rms_px = 0;
  std::vector<int> stereo_views;
  std::vector<std::string> warnings;  // poor coverage or tilt, many rejected views
};

// Throws InputError naming `source` when too few views see the board (fewer than 6 per camera or
// 4 in both), or when the solve fails.
StereoCalibrationResult calibrate_stereo(const std::vector<StereoView>& views, const BoardSpec& board,
                                         cv::Size image_size, const CalibrationOptions& options,
                                         const std::string& source);

}  // namespace plslam::calib
