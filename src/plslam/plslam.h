#pragma once
// plslam's public API: stereo point-line SLAM behind one class, for programs that embed it.
// Include this header only; link `plslam::plslam` (find_package(plslam)). docs/api.md has a
// complete example. The other headers under plslam/ are installed too, for the stages one by one,
// but they change between versions; this one is kept stable.
//
//   plslam::Slam slam(plslam::read_calibration("stereo.yaml"));
//   for (...) {
//     const auto f = slam.track(left, right, t);      // rectified stereo pair, seconds
//     if (f.tracked) use(f.T_world_camera);
//   }
//   slam.shutdown();                                     // local mapping and loop closing finish
//   slam.save_map("office.plmap");
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/core/error.h"  // InputError: bad input, one line naming the file
#include "plslam/core/imu.h"    // ImuData
#include "plslam/core/types.h"  // StereoCalibration, StampedPose, Trajectory

namespace plslam {

namespace system {
class System;
}

// The library's version ("0.1.0").
const char* version();

// Reads a stereo calibration file (YAML: width, height, fx, fy, cx, cy, baseline of the rectified
// pair; README "Video and camera input"). InputError naming the file and key on a missing file, a
// missing or unknown key, or a value that is not positive and finite.
StereoCalibration read_calibration(const std::filesystem::path& file);

// The defaults a preset holds: EuRoC-like (20 Hz, 752x480, 11 cm baseline) or KITTI-like
// (10 Hz, 1241x376, 54 cm baseline) cameras; a config file overrides any key of it.
enum class Preset { kEuroc, kKitti };

struct SlamOptions {
  Preset preset = Preset::kEuroc;
  std::filesystem::path config_file;  // YAML over the preset (config/*.yaml); empty: the preset alone
  std::filesystem::path vocabulary;   // empty: the vocabulary shipped with plslam
  bool lines = true;                  // false: points only
  bool place_recognition = true;      // relocalization after loss (needs the vocabulary)
  bool loop_closing = true;           // needs place recognition
  // Local mapping and loop closing run inside track() instead of their own threads: slower, and
  // the poses are the same from run to run (the debugging mode).
  bool sequential = false;
  // The default: local mapping and loop closing on their own threads, met at frames fixed in
  // advance (README "How the threads meet"), so the poses are the same from run to run. false: the
  // free-running pipeline, whose threads meet whenever they are done (results differ from run to
  // run, and local mapping skips BAs when it falls behind). Ignored with sequential.
  bool deterministic = true;
  // With load_map(): track in the loaded map without adding keyframes, points or lines.
  bool localization_only = false;
};

enum class TrackingState { kNotInitialized, kTracking, kLost };
const char* to_string(TrackingState state);

// What a frame's pose is worth: "tracked", "relocalized" (confirmed a relocalization) and
// "localized" (in a loaded map, localization only) are poses plslam stands behind; "recovering"
// (tracked from a relocalization not yet confirmed), "unanchored" (tracked in a new map segment
// that no loop has tied to the map: its place in the world is a guess) and "lost" are not.
// "inertial": vision could not track the frame (no texture) and the IMU carried its pose for a
// few seconds at most (Slam::use_imu): trusted.
enum class FrameState { kLost, kRecovering, kRelocalized, kTracked, kLocalized, kUnanchored, kInertial };
const char* to_string(FrameState state);

struct TrackedFrame {
  long index = 0;          // 0, 1, 2, ... in the order track() was called
  double timestamp = 0;    // seconds, as given
  TrackingState state = TrackingState::kNotInitialized;
  FrameState frame_state = FrameState::kLost;
  // T_world_camera is a trusted estimate (frame_state tracked, relocalized, localized or inertial).
  bool tracked = false;
  // The left camera in the world (maps camera coordinates to world coordinates); the world is the
  // first keyframe's camera, or the loaded map's world.
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  int point_inliers = 0;
  int line_inliers = 0;
  // The covariance of the pose's final optimisation (the inverse of its information matrix, for
  // 1 px of noise at the finest level): of xi in T_world_camera_true = T_world_camera exp(xi), xi =
  // (translation in m, rotation in rad) in the camera's own frame. Zero when the frame has no pose.
  Eigen::Matrix<double, 6, 6> pose_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool keyframe = false;         // the frame became a keyframe
  bool relocalized = false;      // confirmed being found again in the map after being lost
  bool new_map_segment = false;  // lost for too long: a new, disconnected map started
  double tracking_ms = 0;        // images in to pose out
};

// A copy of the map at one moment, as plain arrays (rows are landmarks).
struct MapSnapshot {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> points;  // x y z
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> lines;   // x y z of both endpoints
  std::vector<long> point_ids, line_ids;
  Trajectory keyframes;  // T_world_camera of every keyframe, by time
  // The map's change counter when the copy was taken: Slam::map_changes() differs once the map
  // has changed (a viewer copies it again only then).
  long changes = 0;
};

struct SlamStats {
  long frames = 0;           // track() calls
  long tracked = 0;          // of them, with a pose
  long lost_events = 0;
  long relocalizations = 0;
  long loops = 0;            // loops closed
  std::size_t keyframes = 0, points = 0, lines = 0;  // in the map now
  // With use_imu(): the visual-inertial initialisation was accepted and the world turned to the
  // gravity-aligned one (z up; poses from then on, and trajectory() and map() wholly, are in it).
  bool gravity_aligned = false;
};

// A recorded sequence in the EuRoC/ASL or KITTI odometry layout, as `plslam run` reads it:
// rectified grey stereo pairs, the calibration, and the ground truth of the left camera.
struct StereoImages {
  double timestamp = 0;  // seconds
  cv::Mat left, right;   // 8-bit grey, rectified
};

class Sequence {
 public:
  // InputError naming the file on a missing or malformed folder.
  explicit Sequence(const std::filesystem::path& folder);
  ~Sequence();
  Sequence(Sequence&&) noexcept;
  Sequence& operator=(Sequence&&) noexcept;

  std::size_t size() const;
  const StereoCalibration& calibration() const;
  Preset preset() const;  // KITTI layout: kKitti, else kEuroc
  // Frame i (0-based); InputError naming the image when it cannot be read.
  StereoImages frame(std::size_t i) const;
  // T_world_camera of the left camera; null when the sequence has none.
  const Trajectory* ground_truth() const;
  // The IMU (EuRoC's mav0/imu0), cut to the frames +-0.5 s; null when the sequence has none.
  const ImuData* imu() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The errors `plslam eval` reports, after an SE(3) alignment of the estimate to the ground truth
// (pairs associated by time, within 10 ms). InputError with fewer than 3 pairs.
struct TrajectoryErrors {
  std::size_t pairs = 0;
  double ate_rmse_m = 0;       // absolute position error
  double rpe_trans_rmse_m = 0; // frame-to-frame relative error
  double rpe_rot_rmse_deg = 0;
};
TrajectoryErrors evaluate_trajectory(const Trajectory& ground_truth, const Trajectory& estimate);

// Not thread-safe: call every member from one thread (the tracking thread). Its own threads (local
// mapping, loop closing) stop in shutdown() or the destructor.
class Slam {
 public:
  // InputError when the calibration, the config file or the vocabulary is bad.
  explicit Slam(const StereoCalibration& calibration, const SlamOptions& options = {});
  ~Slam();
  Slam(Slam&&) noexcept;
  Slam& operator=(Slam&&) noexcept;
  Slam(const Slam&) = delete;
  Slam& operator=(const Slam&) = delete;

  // One rectified stereo pair of the calibration's size, 8-bit grey or BGR. Timestamps must
  // increase. InputError on a wrong size or type; std::logic_error after shutdown().
  TrackedFrame track(const cv::Mat& left, const cv::Mat& right, double timestamp);

  // Every tracked frame with the map's current estimate of it (keyframes move under bundle
  // adjustment and loop closing, and frames move with them).
  Trajectory trajectory() const;
  // A consistent copy (no optimisation is seen half written back); safe while the threads run.
  MapSnapshot map() const;
  long map_changes() const;
  SlamStats stats() const;
  const StereoCalibration& calibration() const;

  // Before the first track(): the IMU of the sequence (a copy). As `plslam run` with an IMU: the
  // visual-inertial initialisation runs on the tracked frames and, once accepted, the world turns
  // to the gravity-aligned one (README, "The world frame, with and without an IMU"); tracking does
  // not use the IMU otherwise yet. Ignored with localization_only. std::logic_error after the
  // first track().
  void use_imu(const ImuData& imu);
  // Before the first track(): continues (or, with localization_only, localizes in) a map saved by
  // save_map() or `plslam run --save-map`. InputError when the file is bad or was made with another
  // calibration or vocabulary.
  void load_map(const std::filesystem::path& file);
  // Finishes the run (shutdown()) and writes the map; the file appears whole or not at all.
  void save_map(const std::filesystem::path& file);

  // Lets local mapping and loop closing finish their queues and stops their threads; the
  // trajectory and map are final after it. Called by the destructor.
  void shutdown();
  bool is_shut_down() const;

  // The system underneath, for what this class does not offer (unstable API).
  system::System& system();
  const system::System& system() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plslam
