#pragma once
// Stereo datasets behind one interface. A Dataset knows its calibration (already rectified),
// frame list and ground truth; images are decoded on demand, and FrameStream prefetches them
// on a background thread with a bounded queue so memory does not grow with sequence length.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/core/error.h"
#include "plslam/core/imu.h"
#include "plslam/core/types.h"
#include "plslam/geometry/stereo_rectification.h"

namespace plslam::io {

// kVideo: a side-by-side stereo video with a calibration file (io/video_dataset.h); never
// detected, the user names it.
enum class DatasetFormat { kAuto, kKitti, kEuroc, kVideo };

const char* to_string(DatasetFormat f);
DatasetFormat parse_dataset_format(const std::string& name);  // auto|kitti|euroc

// Thrown by Dataset::load(i) of an input that is decoded in order (a video) when it ended before
// frame i although its header counted more frames: there is no frame i or later, and the frame
// stream ends there instead of trying each of them.
class InputEnded : public InputError {
 public:
  using InputError::InputError;
};

struct StereoFrame {
  std::size_t index = 0;  // index within the selected range
  double timestamp = 0;   // seconds
  cv::Mat left, right;    // 8-bit grey, rectified
  std::filesystem::path left_path, right_path;
  // Why the frame cannot be used although it decoded (a blank image), empty when it can; the
  // frame stream skips such frames like unreadable ones, or passes the blank ones on when asked
  // (FrameStream's deliver_blank: the IMU may carry the camera through them).
  std::string problem;
  bool blank = false;  // the problem is a blank image (every pixel one value)
};

struct DatasetOptions {
  DatasetFormat format = DatasetFormat::kAuto;
  std::size_t start = 0;                       // first frame to use
  std::optional<std::size_t> max_frames;       // at most this many frames
  // An IMU for a video (--imu, --imu-calib; see open_video_dataset), both or neither. A dataset
  // folder has its own (EuRoC's mav0/imu0) or none (KITTI): open_dataset refuses these.
  std::filesystem::path imu_csv, imu_calib;
  // The rectified field of view of inputs rectified on reading (geometry/stereo_rectification.h).
  double rectify_balance = 0.0;
  // A raw calibration file (io/camchain_file.h) in place of an EuRoC folder's two sensor.yaml
  // (--calib); KITTI, whose images come rectified, refuses it.
  std::filesystem::path calibration;
};

// The raw cameras of an input that is rectified on reading, and what rectification kept of them.
struct RawRig {
  geometry::RawStereoRig rig;
  double balance = 0;
  geometry::RectificationCoverage coverage;
};

class Dataset {
 public:
  virtual ~Dataset() = default;

  virtual DatasetFormat format() const = 0;
  const std::filesystem::path& root() const { return root_; }
  const StereoCalibration& calibration() const { return calib_; }
  std::size_t size() const { return timestamps_.size(); }
  const std::vector<double>& timestamps() const { return timestamps_; }
  double fps() const;  // median frame rate; 0 with fewer than two frames

  // Ground truth of the left camera (T_world_leftcam), restricted to the selected range where
  // the format pairs it by index (KITTI), or the whole file's overlap in time (EuRoC).
  const std::optional<Trajectory>& ground_truth() const { return gt_; }
  const std::filesystem::path& ground_truth_path() const { return gt_path_; }
  // Path length of the ground truth in metres (0 without ground truth).
  double ground_truth_length() const;

  // Rotation from the raw left sensor frame to the rectified left camera frame (identity for
  // KITTI, whose images come rectified). Ground truth is given for the raw left sensor, as
  // datasets and published tables do: T_w_rect = T_w_sensor * R_rect_sensor^T.
  const Eigen::Matrix3d& rectification_rotation() const { return R_rect_sensor_; }
  // The raw rig for inputs rectified on reading (EuRoC); nullopt for those that come rectified.
  const std::optional<RawRig>& raw_rig() const { return raw_rig_; }

  // The input's IMU on the frames' clock, its samples cut to the selected frames plus
  // kImuMarginS (io/imu_input.h) on each side; nullopt without one (KITTI, an EuRoC sequence
  // without mav0/imu0, a video without --imu). imu_path() is its sample file.
  const std::optional<ImuData>& imu() const { return imu_; }
  const std::filesystem::path& imu_path() const { return imu_path_; }

  // Loads and rectifies frame i (0-based within the selected range). A missing or corrupt image
  // throws InputError naming the file.
  virtual StereoFrame load(std::size_t i) const = 0;

 protected:
  std::filesystem::path root_;
  StereoCalibration calib_;
  std::vector<double> timestamps_;
  std::optional<Trajectory> gt_;
  std::filesystem::path gt_path_;
  Eigen::Matrix3d R_rect_sensor_ = Eigen::Matrix3d::Identity();
  std::optional<RawRig> raw_rig_;
  std::optional<ImuData> imu_;
  std::filesystem::path imu_path_;
};

// InputError(file, ...) unless the calibration holds finite intrinsics, positive focal lengths and
// a positive baseline (the image size is not checked: a KITTI calib.txt does not hold it).
void validate_calibration(const StereoCalibration& c, const std::filesystem::path& file);

// Opens a KITTI odometry sequence folder (sequences/NN) or an EuRoC/ASL sequence (<seq> or
// <seq>/mav0). Throws InputError with the offending file and problem on bad input.
std::unique_ptr<Dataset> open_dataset(const std::filesystem::path& path,
                                      const DatasetOptions& options = {});

}  // namespace plslam::io
