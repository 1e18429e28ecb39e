#pragma once
// A synthetic stereo sequence: scene + camera preset + trajectory + sensor model. Frames are
// rendered on demand and independently (any order, any thread with its own StereoRenderer),
// and always give the same bytes for the same options.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "plslam/calib/board.h"
#include "plslam/core/types.h"
#include "plslam/geometry/lens_model.h"
#include "plslam/synth/lens_renderer.h"
#include "plslam/synth/renderer.h"
#include "plslam/synth/scene.h"
#include "plslam/synth/sensor.h"
#include "plslam/synth/trajectory.h"

namespace plslam::synth {

struct CameraPreset {
  std::string name;
  int width, height;
  double fps;
  double fx, fy, cx, cy;
  double baseline;  // metres
};

CameraPreset euroc_preset();  // 752x480, 20 Hz, fx 458, baseline 0.11 m
CameraPreset kitti_preset();  // 1241x376, 10 Hz, fx 718, baseline 0.54 m
CameraPreset parse_preset(const std::string& name);  // euroc|kitti; InputError otherwise

// pinhole: the ideal rectified pair (no distortion, parallel cameras). radtan and equidistant: a
// real rig, as a calibration finds one: EuRoC-like radial-tangential or TUM-VI-like equidistant
// lenses with slightly different intrinsics per camera, and the right camera turned by 0.4 degrees.
enum class CameraKind { kPinhole, kRadialTangential, kEquidistant };
CameraKind parse_camera_kind(const std::string& name);  // pinhole|radtan|equidistant; InputError otherwise
const char* to_string(CameraKind kind);

struct SequenceOptions {
  SceneKind scene = SceneKind::kOffice;
  CameraPreset preset = euroc_preset();
  int frames = 200;
  std::uint64_t seed = 1;
  // 0: the scene's own path; others: another path through the same scene (PathVariation).
  std::uint64_t path_seed = 0;
  bool loop = false;         // traverse the whole closed path (>= 30 m) and return to the start
  double loop_overlap = 0.03;  // with loop: share of the path travelled again after the return, in [0, 1]
  bool motion_blur = false;  // integrate over the shutter time, proportional to the motion
  MotionProfile motion = MotionProfile::kWalk;
  CameraKind camera = CameraKind::kPinhole;
  // Diagonal field of view in degrees, which sets the focal length; 0 keeps the preset's.
  double fov_deg = 0;
  calib::BoardSpec board;  // SceneKind::kCalibration's board
};

class Sequence {
 public:
  explicit Sequence(const SequenceOptions& options);  // throws InputError on bad options

  const SequenceOptions& options() const { return options_; }
  const Scene& scene() const { return scene_; }
  const CameraPath& path() const { return path_; }
  const SensorModel& sensor() const { return sensor_; }
  // The rectified calibration: of an ideal pair (CameraKind::kPinhole) only, InputError otherwise.
  StereoCalibration calibration() const;
  geometry::LensCamera lens(int cam) const;  // cam 0: left, 1: right
  // The right camera's pose in the left camera's frame (p_left = T_left_right * p_right).
  const Eigen::Isometry3d& T_left_right() const { return T_lr_; }
  std::size_t size() const { return static_cast<std::size_t>(options_.frames); }
  double time(std::size_t i) const { return static_cast<double>(i) / options_.preset.fps; }
  // T_world_left: on the path, or the calibration scene's views.
  Eigen::Isometry3d left_pose(std::size_t i) const { return views_.empty() ? path_.pose(time(i)) : views_.at(i); }
  bool has_path() const { return views_.empty(); }  // a continuous motion (and an IMU) rather than views
  Eigen::Isometry3d right_pose(std::size_t i) const;

 private:
  SequenceOptions options_;
  Scene scene_;
  CameraPath path_;
  SensorModel sensor_;
  std::array<geometry::LensCamera, 2> lens_;
  Eigen::Isometry3d T_lr_;
  std::vector<Eigen::Isometry3d> views_;
};

struct StereoImages {
  cv::Mat left, right;              // CV_8U
  cv::Mat left_depth, right_depth;  // CV_32F metres (only when requested)
};

// Per-thread rendering state (z-buffers) for one sequence.
class StereoRenderer {
 public:
  explicit StereoRenderer(const Sequence& sequence);
  StereoImages render(std::size_t i, bool with_depth = false);

 private:
  void render_camera(int cam, std::size_t i, cv::Mat& radiance, cv::Mat* depth);

  const Sequence& seq_;
  std::array<LensRenderer, 2> renderers_;
  cv::Mat radiance_, accum_;
};

}  // namespace plslam::synth
