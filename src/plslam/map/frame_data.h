#pragma once
// Everything extracted from one rectified stereo pair, immutable once built: stereo keypoints,
// stereo line segments, and a grid over the left image for fast projection search. Frames and the
// keyframes made from them share one FrameData.
#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plslam/core/types.h"
#include "plslam/features/line_segment.h"
#include "plslam/optim/observations.h"

namespace plslam::map {

struct LineObservation {
  features::LineSegment segment;  // left image, level-0 pixels
  // Image lines a u + b v + c = 0 with a^2 + b^2 = 1: through the left segment, and through the
  // matched right segment when `stereo`.
  Eigen::Vector3d left_line = Eigen::Vector3d::Zero();
  Eigen::Vector3d right_line = Eigen::Vector3d::Zero();
  bool stereo = false;
  Eigen::Vector3d start_cam = Eigen::Vector3d::Zero();  // 3D endpoints in the left camera (stereo only)
  Eigen::Vector3d end_cam = Eigen::Vector3d::Zero();
};

struct FrameData {
  long frame_id = 0;
  double timestamp = 0;
  StereoCalibration calib;
  int levels = 8;
  double scale_factor = 1.2;

  std::vector<cv::KeyPoint> keypoints;  // left image, level-0 pixels, octave = level
  cv::Mat descriptors;                  // N x 32 CV_8U
  std::vector<float> u_right;           // -1 when no stereo match
  std::vector<float> depth;             // metres, -1 when no stereo match

  std::vector<LineObservation> lines;
  cv::Mat line_descriptors;  // M x 32 CV_8U (LBD)

  // Grid of keypoint indices over the left image, built by build_grid(): the indices of cell c
  // (row-major) are grid_indices[grid_offsets[c] .. grid_offsets[c + 1]), increasing. Two flat
  // arrays instead of a vector per cell: one allocation each, for every frame and every keyframe
  // read from a map file.
  static constexpr int kGridCols = 64, kGridRows = 48;
  std::vector<int> grid_offsets;
  std::vector<int> grid_indices;
  bool has_grid() const { return !grid_offsets.empty(); }

  void build_grid();
  // Indices of keypoints within radius r of (u, v) whose level lies in [min_level, max_level]
  // (max_level < 0: no upper bound).
  std::vector<int> points_in_area(double u, double v, double r, int min_level = 0, int max_level = -1) const;

  // Whether keypoint i's right-image match constrains optimisation: it has one, and its depth is
  // at most `max_depth_baselines` baselines (<= 0: any depth). Beyond that the match still gives
  // the point its first depth, but a constant disparity error of a fraction of a pixel (imperfect
  // rectification) would bias the scale through the far points; their left-image observations
  // keep constraining rotation (ORB-SLAM2's close/far split).
  bool stereo_constraint(std::size_t i, double max_depth_baselines) const {
    return u_right[i] >= 0 && (max_depth_baselines <= 0 || depth[i] <= max_depth_baselines * calib.baseline);
  }
  // Keypoint i as an optimiser's observation: (u_l, v, u_r), its level, and the right column used
  // as stereo_constraint(i, max_depth_baselines) says. Keyframe and point indices are left 0.
  optim::StereoPointObservation point_observation(std::size_t i, double max_depth_baselines = 0) const;

  double level_scale(int level) const;        // scale_factor^level
  double level_sigma2(int level) const;       // scale_factor^(2 level)
  std::size_t num_points() const { return keypoints.size(); }
  std::size_t num_lines() const { return lines.size(); }
};

}  // namespace plslam::map
