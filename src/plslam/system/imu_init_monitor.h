#pragma once
// Visual-inertial initialisation during a run (inertial/vi_initializer.h): the tracked frames'
// poses since tracking began, with the input's IMU, are tried every `attempt_every_s` until an
// initialisation is accepted. A frame without a trusted pose breaks the motion and starts the
// window again. The system (slam_system.h) turns its world to the gravity-aligned one once it is
// accepted; tracking does not use the IMU otherwise yet.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "plslam/core/imu.h"
#include "plslam/inertial/vi_initializer.h"

namespace plslam::system {

struct ImuInitMonitorOptions {
  inertial::ViInitOptions init;
  double attempt_every_s = 0.5;  // an attempt takes 10-130 ms (5 s of frames)
  double min_frame_spacing_s = 0.09;  // frames closer than this to the last one kept add little
  double max_window_s = 5;            // the oldest frames leave a longer window
};

class ImuInitMonitor {
 public:
  ImuInitMonitor(const ImuData& imu, ImuInitMonitorOptions options = {});

  // One frame: its time and pose (T_world_camera), nullopt when it has no trusted pose.
  void add(double timestamp, const std::optional<Eigen::Isometry3d>& T_world_camera);
  bool initialised() const { return accepted_.has_value(); }
  // The accepted initialisation, else the last attempt (refused), else nothing tried yet.
  const std::optional<inertial::ViInitResult>& result() const { return accepted_ ? accepted_ : last_; }
  // Seconds of tracked motion the accepted initialisation used (from the window's first frame).
  double seconds_of_motion() const { return seconds_; }
  int attempts() const { return attempts_; }

  nlohmann::json report() const;
  std::string summary() const;  // one line for the log

 private:
  const ImuData& imu_;
  ImuInitMonitorOptions options_;
  std::vector<inertial::ViKeyframe> window_;
  double last_attempt_t_ = -1e300;
  int attempts_ = 0;
  double seconds_ = 0;
  double accepted_at_ = 0;
  std::optional<inertial::ViInitResult> last_, accepted_;
  struct Attempt {
    double t, span_s, gravity_sigma_deg;
  };
  std::vector<Attempt> history_;
};

}  // namespace plslam::system
