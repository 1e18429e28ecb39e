#pragma once
// Stereo matching of line segments on a rectified pair. A left line may match a right line
// when their orientations agree, their row extents overlap, both endpoint disparities are
// positive and below the maximum, and their LBD descriptors pass a threshold and ratio test
// (best of both directions). Each left endpoint's row is intersected with the right line to get
// that endpoint's disparity; near-horizontal lines are rejected because that intersection is
// ill-conditioned there.
#include <vector>

#include <Eigen/Core>

#include "plslam/core/types.h"
#include "plslam/features/line_extractor.h"

namespace plslam::matching {

struct StereoLineMatchOptions {
  int max_hamming = 80;                       // of 256 bits
  double ratio = 0.9;                         // best < ratio * second best
  double min_angle_from_horizontal_deg = 10;  // reject flatter left lines
  double max_angle_difference_deg = 5;        // directed orientation, left vs right
  double min_row_overlap = 0.5;               // of the shorter line's row extent
  double min_depth_m = 0.5;                   // max disparity = bf / min_depth
  bool cross_check = true;                    // require the left line to be the right's best too
};

struct StereoLineMatch {
  int left = -1, right = -1;  // indices into the left/right LineFeatures
  int distance = 0;           // Hamming distance of the descriptors
  double disparity_start = 0, disparity_end = 0;
  Eigen::Vector3d P_start, P_end;  // 3D endpoints in the left camera frame (metres)
  // l = (p_s x p_e) / (|p_s| |p_e|) with homogeneous pixel endpoints p = (u, v, 1).
  Eigen::Vector3d coefficients;
};

// Normalised line coefficients of a left segment, as in the paper.
Eigen::Vector3d line_coefficients(const cv::Point2f& start, const cv::Point2f& end);

// Column where the (infinite) line through s crosses image row y; s must not be horizontal.
double column_at_row(const features::LineSegment& s, double y);

// The match of left segment `a` with endpoint disparities ds and de (positive): its 3D endpoints
// back-projected at depth bf / d, and its coefficients.
StereoLineMatch make_stereo_line_match(int left, int right, int distance, const features::LineSegment& a, double ds,
                                       double de, const StereoCalibration& calib);

std::vector<StereoLineMatch> match_stereo_lines(const features::LineFeatures& left,
                                                const features::LineFeatures& right,
                                                const StereoCalibration& calib,
                                                const StereoLineMatchOptions& options = {});

}  // namespace plslam::matching
