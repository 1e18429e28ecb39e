#pragma once
// What `plslam calibrate` tells its user: a JSON report of the result (against a known truth when
// there is one) and an image of where the board's corners fell and how large their reprojection
// errors are, per camera, over the coverage grid the view selection uses.
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "plslam/calib/stereo_calibration.h"
#include "plslam/geometry/stereo_rectification.h"

namespace plslam::calib {

nlohmann::json lens_json(const geometry::LensCamera& lens);
nlohmann::json transform_json(const Eigen::Isometry3d& T);  // 4 rows of 4

// The result as JSON: cameras (intrinsics, coefficients, RMS, views, rejected frames, coverage,
// tilt), the stereo pose (T_cn_cnm1, baseline, rotation angle, RMS) and the warnings.
nlohmann::json calibration_json(const StereoCalibrationResult& result);

// How far `estimate` is from `truth`: focal lengths (%), principal points (px), baseline (%), the
// rotation between the cameras (deg), and the largest pixel distance between the two lens models'
// projections of the same ray over the image.
nlohmann::json calibration_error_json(const geometry::RawStereoRig& estimate, const geometry::RawStereoRig& truth);

// Left and right camera side by side, each of the image's size: the coverage grid's cells (green
// where a corner fell, red where none did), every corner of the kept views as a dot coloured by its
// error (green below 0.3 px, yellow below 1 px, red above), its error vector drawn 50 times longer,
// and a caption with the camera's RMS, views and coverage. 8-bit BGR.
cv::Mat draw_coverage(const StereoCalibrationResult& result, cv::Size image_size, const CalibrationOptions& options);

// The rig the result describes.
geometry::RawStereoRig rig_of(const StereoCalibrationResult& result);

}  // namespace plslam::calib
