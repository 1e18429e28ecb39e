#pragma once
// Merging of segments that one physical edge was broken into (LSD and region growing break
// edges at noise, occluders and texture). Candidates are gated in Hough space about the image
// centre, then must also be close along the line: without the gap test, distant collinear
// edges (two window frames in a row) would fuse.
#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/line_segment.h"

namespace plslam::features {

struct LineMergeOptions {
  double max_rho_fraction = 0.01;   // |drho| below this fraction of the half image diagonal
  double max_theta_deg = 1.0;       // |dtheta| below this
  double max_gap_px = 20.0;         // free space between the pieces along the line
  double max_overlap_px = 10.0;     // pieces may overlap along the line by at most this
  double max_endpoint_distance_px = 2.0;  // shorter piece's endpoints to the longer one's line
  bool same_polarity = true;        // only merge pieces with the same bright side
};

// Frame in which the Hough gate is evaluated.
struct MergeFrame {
  cv::Point2f centre;
  double half_diagonal = 1.0;
  static MergeFrame of(cv::Size image_size);
};

// Whether b may be merged into a (a is taken as the reference line; pass the longer first).
bool can_merge(const LineSegment& a, const LineSegment& b, const MergeFrame& frame,
               const LineMergeOptions& options);

// Least-squares line through the endpoints of a and b (weighted by their lengths), extended to
// the extreme projections of all four endpoints. Orientation follows a.
LineSegment fuse_segments(const LineSegment& a, const LineSegment& b);

// Merges until no pair qualifies. Result responses are the merged lengths; `fragments` counts
// how many input segments each output absorbed.
std::vector<LineSegment> merge_segments(std::vector<LineSegment> segments, cv::Size image_size,
                                        const LineMergeOptions& options = {});

// Keeps the n segments with the highest response (length), longest first.
void keep_best(std::vector<LineSegment>& segments, std::size_t n);

}  // namespace plslam::features
