#pragma once
// Writes a Sequence to disk in the layout of a real dataset, plus extra ground truth:
//
//   EuRoC (--format euroc):
//     DIR/mav0/cam{0,1}/data.csv, data/<ns>.png, sensor.yaml   (exactly the ASL layout)
//     DIR/mav0/imu0/data.csv, sensor.yaml                     (the synthetic IMU, synth/imu_synth.h)
//     DIR/mav0/state_groundtruth_estimate0/data.csv           (body = IMU frame: pose, velocity,
//                                                              true gyro and accelerometer biases)
//     DIR/mav0/synth/                                         (extra ground truth, below)
//   KITTI (--format kitti):
//     DIR/sequences/00/{image_0,image_1}/NNNNNN.png, calib.txt, times.txt
//     DIR/poses/00.txt                                        (left camera, first pose identity)
//     DIR/sequences/00/synth/                                 (extra ground truth, below)
//   Side-by-side video (--format video), as `plslam run --video` reads it:
//     DIR/stereo.mkv          left | right in each frame, FFV1 (lossless) grey, at the preset's rate
//     DIR/calibration.yaml    the rectified calibration (io/calibration_file.h)
//     DIR/ground_truth.tum    left camera in the scene's world, seconds from the first frame
//     DIR/synth/                                              (extra ground truth, below)
//
//   synth/segments_3d.txt   "x1 y1 z1 x2 y2 z2" per line: every straight scene edge
//   synth/points_3d.txt     "x y z" per line: surface sample points
//   synth/left_camera.tum   TUM poses of the left camera (T_world_left) at the image times
//   synth/synth.json        the options (scene, preset, seed, loop, ...) and the frame used;
//                           written last, so its presence marks a complete sequence
// All synth/ coordinates are in the frame of that layout's ground truth: the EuRoC world
// (z up), for KITTI the first left camera, for the video the scene's world.
#include <filesystem>
#include <functional>

#include <Eigen/Geometry>

#include "plslam/synth/imu_synth.h"
#include "plslam/synth/sequence.h"

namespace plslam::synth {

enum class OutputFormat { kEuroc, kKitti, kVideo };
OutputFormat parse_output_format(const std::string& name);  // euroc|kitti|video; InputError otherwise

// File names of the video layout inside DIR.
inline constexpr const char* kVideoFile = "stereo.mkv";
inline constexpr const char* kVideoCalibrationFile = "calibration.yaml";

// Sensor-to-body transform of cam0 used in the EuRoC layout (p_body = T_BS * p_cam0).
Eigen::Isometry3d euroc_T_BS_cam0();
// EuRoC image timestamp of frame i in nanoseconds.
std::int64_t euroc_timestamp_ns(const Sequence& seq, std::size_t i);

// Called after each frame is written with (frames done, total).
using Progress = std::function<void(std::size_t, std::size_t)>;

// Polled before each frame; true stops the rendering (a signal asked the program to stop).
using Cancelled = std::function<bool()>;

// Renders every frame (in parallel when `threads` != 1) and writes the dataset into `dir`.
// Returns false, with the dataset incomplete, when `cancelled` stopped it.
// The EuRoC layout also gets the IMU of `imu` (the other layouts have none).
bool write_sequence(const Sequence& seq, const std::filesystem::path& dir, OutputFormat format,
                    const Progress& progress = {}, int threads = 0, const Cancelled& cancelled = {},
                    const ImuSynthOptions& imu = {});

// The seed of the IMU's noise and biases for a sequence.
std::uint64_t imu_seed(const SequenceOptions& o);

}  // namespace plslam::synth
