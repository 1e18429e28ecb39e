#pragma once
// Visual-inertial initialisation during a run (inertial/vi_initializer.h): the tracked frames'
// poses since tracking began, with the input's IMU, are tried every `attempt_every_s` until an
// initialisation is accepted. A frame without a trusted pose breaks the motion and starts the
// window again. Part 1 of the IMU work reports the result (stats.json "imu", the summary); tracking
// does not use it yet, and the outputs stay in the first camera's world.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plslam/core/imu.h"
#include "plslam/inertial/vi_initializer.h"
#include "plslam/system/slam_system.h"

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

  void add(const FrameResult& frame);
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
