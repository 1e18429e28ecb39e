#pragma once
// A live V4L2 stereo camera through OpenCV: one device whose frames hold both images side by side
// (left | right, as most USB stereo cameras deliver them), or two devices, one per camera. The
// images must come rectified, as the calibration file describes them.
#include <memory>
#include <string>

#include "plslam/core/types.h"
#include "plslam/geometry/stereo_rectification.h"
#include "plslam/io/live_capture.h"

namespace plslam::io {

// Opens `device` (and `right_device` when not empty), asks for the calibration's frame size and
// reads a first frame to check it. A missing device, one V4L2 cannot open, or frames of another
// size than the calibration's throw InputError naming the device.
//
// A regular file in place of the device is a side-by-side video played at its frame rate, as a
// camera would deliver it, from the moment the capture starts: the live path (and its dropped
// frames) can be tried and tested without a camera.
std::unique_ptr<FrameSource> open_stereo_camera(const std::string& device, const std::string& right_device,
                                                     const StereoCalibration& calibration);

// A source whose raw frames are rectified as they come (for a raw calibration, io/camchain_file.h).
std::unique_ptr<FrameSource> rectify_frames(std::unique_ptr<FrameSource> raw,
                                            const geometry::StereoRectification& rectification);

}  // namespace plslam::io
