#pragma once
// The dataset selection options shared by every command that reads a sequence.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "plslam/core/error.h"
#include "plslam/io/dataset.h"

namespace plslam::cli {

struct DatasetArgs {
  std::string path;
  std::string format = "auto";
  // Signed, so that "-5" is refused by the range check instead of wrapping around.
  long long start = 0;
  long long max_frames = -1;
  std::string imu;        // --imu FILE (add_imu_options)
  std::string imu_calib;  // --imu-calib FILE
  double balance = 0.0;   // --balance

  io::DatasetOptions options() const {
    io::DatasetOptions o;
    o.format = io::parse_dataset_format(format);
    o.start = static_cast<std::size_t>(start);
    if (max_frames >= 0) o.max_frames = static_cast<std::size_t>(max_frames);
    o.imu_csv = imu;
    o.imu_calib = imu_calib;
    o.rectify_balance = balance;
    return o;
  }
};

// The largest frame count or index taken from the command line: far above any real sequence, and
// small enough that every count derived from it stays exact.
inline constexpr long long kMaxFrameArg = 1'000'000'000;

// `max_frames_names` lets `bench` keep its shorter "--frames" alias; `run` takes other inputs
// too, so its dataset folder is optional.
inline void add_dataset_options(CLI::App& sub, DatasetArgs& args,
                                const std::string& max_frames_names = "--max-frames", bool required = true) {
  sub.add_option("dataset", args.path, "Sequence folder: KITTI sequences/NN, or EuRoC <seq> or <seq>/mav0")
      ->required(required);
  sub.add_option("--format", args.format, "Dataset format")
      ->check(CLI::IsMember({"auto", "kitti", "euroc"}))
      ->capture_default_str();
  sub.add_option("--start", args.start, "First frame to use")
      ->check(CLI::Range(0LL, kMaxFrameArg))
      ->capture_default_str();
  sub.add_option(max_frames_names, args.max_frames, "Use at most this many frames (-1: all)")
      ->check(CLI::Range(-1LL, kMaxFrameArg))
      ->capture_default_str();
  sub.add_option("--balance", args.balance,
                 "Rectified field of view of an input rectified on reading (an EuRoC folder, or a raw --calib): 0 keeps "
                 "only pixels both cameras see, 1 the whole raw field of view along the image's middle lines, with "
                 "black borders. A fisheye cannot be rectified whole: `plslam info` shows how much is kept")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
}

// --imu and --imu-calib, for the commands that take video or camera input (a dataset folder
// brings its own IMU, or none).
inline void add_imu_options(CLI::App& sub, DatasetArgs& args) {
  sub.add_option("--imu", args.imu,
                 "IMU samples for --video or --camera, in EuRoC's imu0/data.csv layout (ns, gyro xyz rad/s, acc xyz "
                 "m/s^2), needs --imu-calib. Timestamps in ns on the frames' clock: 0 at the video's first frame, "
                 "frame i at i / fps (--camera: the same for a video file; a V4L2 device's clock starts when plslam "
                 "opens it)");
  sub.add_option("--imu-calib", args.imu_calib,
                 "The IMU's sensor.yaml (EuRoC's imu0 layout: T_BS, rate_hz, noise densities and random walks), for "
                 "--imu; its body frame is the rectified left camera (T_BS: the IMU's pose in it)");
}

// Usage errors (exit 2): --imu and --imu-calib go together, and not with a dataset folder.
inline void check_imu_args(const DatasetArgs& args) {
  if (args.imu.empty() != args.imu_calib.empty()) {
    throw InputError("", args.imu.empty() ? "--imu-calib needs --imu FILE" : "--imu needs --imu-calib FILE");
  }
  if (!args.imu.empty() && !args.path.empty()) {
    throw InputError(args.path, "--imu is for --video and --camera input: an EuRoC folder's IMU is its mav0/imu0, "
                                "and KITTI has none");
  }
}

}  // namespace plslam::cli
