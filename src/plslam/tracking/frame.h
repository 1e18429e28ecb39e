#pragma once
// The frame being tracked: its extracted features (shared with the keyframe it may become), its
// pose, and its current associations to map points and map lines.
#include <memory>
#include <optional>
#include <vector>

#include "plslam/geometry/se3.h"
#include "plslam/inertial/imu_bias.h"
#include "plslam/map/frame_data.h"

namespace plslam::map {
class KeyFrame;
class MapPoint;
class MapLine;
}  // namespace plslam::map

namespace plslam::tracking {

struct Frame {
  explicit Frame(std::shared_ptr<const map::FrameData> d)
      : data(std::move(d)),
        points(data->keypoints.size(), nullptr),
        point_outlier(data->keypoints.size(), false),
        lines(data->lines.size(), nullptr),
        line_outlier(data->lines.size(), false) {}

  std::shared_ptr<const map::FrameData> data;
  geometry::SE3 T_cw;
  std::vector<map::MapPoint*> points;
  std::vector<bool> point_outlier;
  std::vector<map::MapLine*> lines;
  std::vector<bool> line_outlier;
  map::KeyFrame* reference = nullptr;
  // Of the last pose optimisation against the local map (optim::PoseOnlyResult::covariance).
  geometry::Matrix6d pose_covariance = geometry::Matrix6d::Zero();
  // Tracked with the IMU (Tracker::use_imu): the body's velocity (world) and the biases.
  struct Imu {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    inertial::ImuBias bias;
  };
  std::optional<Imu> imu;

  long id() const { return data->frame_id; }
  Eigen::Vector3d camera_center() const { return T_cw.inverse().translation(); }
  int num_matched_points() const;
  int num_matched_lines() const;
  // Keypoints with a stereo depth (what starting a map needs, and what a textureless image lacks).
  int num_stereo_points() const;
  // Forgets every point and line association.
  void clear_matches();
  // Drops the associations flagged as outliers (after pose optimisation).
  void discard_outliers();
};

}  // namespace plslam::tracking
