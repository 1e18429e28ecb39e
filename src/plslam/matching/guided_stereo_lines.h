#pragma once
// Stereo lines without detecting lines in the right image: each left segment is searched for
// along its own rows (the epipolar band of a rectified pair). At a few rows along the segment the
// edge is located in both images as the peak of the row derivative with the segment's polarity;
// right candidates must have the same gradient direction and a similar patch (ZNCC). A robust fit
// of disparity, linear in the row as it is for any 3D line, keeps the rows that agree. Detection
// and description of right lines cost as much as the left ones; this search costs a fraction.
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/core/types.h"
#include "plslam/features/line_extractor.h"
#include "plslam/matching/stereo_line_matcher.h"

namespace plslam::matching {

struct GuidedStereoLineOptions {
  int max_samples = 9;          // rows sampled along a segment (fewer on short ones)
  double sample_spacing_px = 8; // ... at most one per this many pixels of segment
  int min_edge_step = 8;        // |I(x+1) - I(x-1)| of an edge candidate, grey levels
  double max_normal_angle_deg = 30;  // right gradient vs the left segment's normal
  int patch_half_width = 4;     // ZNCC window (2 w + 1) x (2 h + 1) pixels
  int patch_half_height = 2;
  double min_zncc = 0.7;
  int candidates_per_row = 3;   // best-scoring right edges kept on the two rows that search widely
  double inlier_px = 1.0;       // disparity residual of a row that agrees with the fit
  double min_inlier_share = 0.6;// of the sampled rows
  int min_inliers = 3;
  // Disparity change per pixel of segment. A street's ground rises about 0.3 px per row on
  // KITTI; far more means two different edges were joined.
  double max_disparity_slope = 1.0;
  // Where the rows alone do not decide (several disparities explain as many rows, or fewer than
  // min_inlier_share but at least this share agree), the LBD descriptor of each candidate right
  // segment (up to `lbd_candidates`) is compared with the left one, as detect-and-describe does.
  double lbd_inlier_share = 0.4;
  int lbd_candidates = 3;
  double lbd_scale = 0.5;  // the line gradient's working scale; the left descriptors' own
  features::LbdOptions lbd;

  void validate() const;  // throws std::invalid_argument naming the bad field
};

// Right edges of one rectified image, row by row: positions of local maxima of |I(x+1) - I(x-1)|
// above the step threshold, with the derivative's sign. Built once per frame.
class RowEdges {
 public:
  RowEdges(const cv::Mat& image, int min_step);
  struct Edge {
    int x;
    short step;    // signed I(x+1) - I(x-1)
    short gx, gy;  // 3x3 sums of the row and column derivatives (the edge's direction)
  };
  // Edges of row y with x in [x0, x1], in increasing x.
  std::pair<const Edge*, const Edge*> range(int y, int x0, int x1) const;

 private:
  std::vector<Edge> edges_;
  std::vector<int> row_start_;  // rows + 1 offsets into edges_
};

// Matches for each non-horizontal left segment (angle from horizontal >= the options' limit),
// with `right` = -1 (no right feature) and `distance` the LBD Hamming distance where the
// descriptor decided (0 where the rows alone did). The left descriptors must have been made
// with the options' lbd_scale and lbd. Endpoint disparities come from the fitted
// disparity at the endpoints' rows, so the right line through (start - d_s, end - d_e) is what
// the optimisers use. Images are the rectified 8-bit pair the left lines were detected on.
std::vector<StereoLineMatch> match_stereo_lines_guided(const features::LineFeatures& left, const cv::Mat& left_image,
                                                       const cv::Mat& right_image, const StereoCalibration& calib,
                                                       const StereoLineMatchOptions& match_options = {},
                                                       const GuidedStereoLineOptions& options = {});

}  // namespace plslam::matching
