#pragma once
// Stereo video input: one video file whose frames hold the left image in their left half and the
// right image in their right half, each `width` x `height` of the user's calibration file
// (io/calibration_file.h). The images must already be rectified; any codec FFmpeg decodes will
// do, a lossless one (FFV1) keeps the images exact.
#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

#include "plslam/io/dataset.h"

namespace plslam::io {

// Opens `video` as a Dataset (format kVideo, root() the video file). Timestamps are the frame
// index over the video's frame rate, from 0 s at its first frame. Ground truth is optional: a
// `ground_truth.tum` beside the video (TUM poses of the left camera, same clock), as
// `plslam synth --format video` writes it. An IMU is read when options names its two files
// (imu_csv, imu_calib; io/imu_input.h): the samples' nanoseconds are on the same clock as the
// frames (0 at the video's first frame, frame i at i / fps), the sensor.yaml's T_BS places the IMU
// in the rectified left camera's frame, and the samples must span the selected frames. Throws
// InputError naming the file for a missing file, one FFmpeg cannot open, frames that are not
// 2 * width x height of the calibration, no frame, or a bad or too short IMU file.
std::unique_ptr<Dataset> open_video_dataset(const std::filesystem::path& video,
                                            const std::filesystem::path& calibration,
                                            const DatasetOptions& options = {});

// The ground-truth file open_video_dataset looks for beside `video`.
std::filesystem::path video_ground_truth_path(const std::filesystem::path& video);

// The left and right halves of a side-by-side frame as separate 8-bit grey images (colour frames
// are converted; the halves are copies). Throws InputError naming `source` unless the frame is
// 2 * width x height.
void split_side_by_side(const cv::Mat& frame, int width, int height, const std::string& source, cv::Mat& left,
                        cv::Mat& right);

// 8-bit grey from a decoded frame (BGR, BGRA or grey), never sharing the frame's buffer.
cv::Mat to_grey(const cv::Mat& frame);

// FFmpeg logs damaged input to stderr by itself; plslam reports it in its own one-line error.
// Call before the process first opens a video.
void quiet_ffmpeg_log();

}  // namespace plslam::io
