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
#include <filesystem>

#include "plslam/core/types.h"

namespace plslam::io {

// Throws InputError naming the file (and the key) on a missing or malformed file, an unknown,
// missing or mistyped key, or a value that is not positive and finite.
StereoCalibration read_calibration_file(const std::filesystem::path& path);

// Writes `calibration` in the format above, atomically (io::write_file_atomically), with a header
// saying what the numbers mean. Read back, it gives the same numbers exactly.
void write_calibration_file(const std::filesystem::path& path, const StereoCalibration& calibration);

}  // namespace plslam::io
