#pragma once
// The stereo calibration a user supplies for a video or a live camera (datasets carry their own):
// a YAML file of seven keys describing RECTIFIED images, as OpenCV's stereoRectify gives them
// (fx = P1(0,0), fy = P1(1,1), cx = P1(0,2), cy = P1(1,2), baseline = -P2(0,3) / P2(0,0)):
//
//   width: 752        # pixels of ONE camera's image (a side-by-side frame is 2 * width wide)
//   height: 480
//   fx: 458.0         # pixels
//   fy: 458.0
//   cx: 375.5
//   cy: 239.5
//   baseline: 0.11    # metres, the right camera sits at +baseline along the left camera's x
//
// Every key is required and must be positive and finite; an unknown key is an error (a typo must
// not pass unnoticed).
//
// A calibration file may instead describe the RAW cameras, as `plslam calibrate` writes it: the
// layout of Kalibr's camchain.yaml (io/camchain_file.h). Inputs are then rectified on reading.
#include <filesystem>
#include <optional>

#include "plslam/core/types.h"
#include "plslam/geometry/stereo_rectification.h"

namespace plslam::io {

// Throws InputError naming the file (and the key) on a missing or malformed file, an unknown,
// missing or mistyped key, or a value that is not positive and finite. A raw (camchain) file is
// refused here: its images need rectifying, which read_user_calibration's callers do.
StereoCalibration read_calibration_file(const std::filesystem::path& path);

// Either form: exactly one of the two is set.
struct UserCalibration {
  std::optional<StereoCalibration> rectified;
  std::optional<geometry::RawStereoRig> raw;
  int width() const { return raw ? raw->left.width : rectified->width; }
  int height() const { return raw ? raw->left.height : rectified->height; }
};
UserCalibration read_user_calibration(const std::filesystem::path& path);

// What an input needs to deliver rectified images: the rectified pair, and for a raw calibration
// the rectification itself (its maps, R_rect_left and coverage; nullopt for the rectified form).
struct InputRectification {
  StereoCalibration calibration;
  std::optional<geometry::StereoRectification> rectification;
};
InputRectification rectify_user_calibration(const UserCalibration& calibration, double balance,
                                            const std::filesystem::path& source);

// Writes `calibration` in the format above, atomically (io::write_file_atomically), with a header
// saying what the numbers mean. Read back, it gives the same numbers exactly.
void write_calibration_file(const std::filesystem::path& path, const StereoCalibration& calibration);

}  // namespace plslam::io
