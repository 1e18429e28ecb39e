#pragma once
// Suppression via Square Covering (SSC, Bailo et al. 2018): keeps about N strong keypoints
// spread homogeneously over the image. Candidates are visited strongest first; a kept point
// covers the grid cells around it, and covered candidates are dropped. The cover width w is
// found by a search between closed-form bounds (derived in ssc.cpp), galloping from a hint.
// Speed (ssc.cpp): one counting sort of the integer FAST scores, then passes that test 8
// candidates at once with AVX2 when the CPU has it (a portable scan gives identical results).
// The extractor passes FastCorners (packed positions and byte scores), which the sort reads
// directly; cv::KeyPoint input is converted first.
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/fast_detector.h"

namespace plslam::features {

struct SscBounds {
  double low = 1;   // at or below this width at least N points survive (distinct integer pixels)
  double high = 1;  // above this width fewer than N points can survive, whatever the input
};

// Bounds on the suppression width for `candidates` keypoints, N = `target`, image `size`.
SscBounds ssc_width_bounds(int candidates, int target, cv::Size size);

struct SscResult {
  std::vector<int> kept;  // indices into the input, strongest first
  double width = 0;       // width of the covering that produced `kept` (0: no suppression)
  int iterations = 0;     // greedy passes run by the search
};

// Selects `target` (+- tolerance_fraction * target) keypoints out of `keypoints`, which lie in
// [0, size.width) x [0, size.height). Any two kept points are more than `width` apart in the
// max-norm. Deterministic: ties in response are broken by input order. When a search step
// overshoots within the tolerance it is returned as is; when the search converges without
// hitting the tolerance the best overshooting covering is cut to exactly `target` (the first
// `target` kept points of a greedy pass are themselves a valid covering result).
// `width_hint` (optional, > 0): a likely width, probed first and then galloped from (steps 1, 1,
// 2, 4, ... towards the outcome) until the outcome flips, so that a good hint (e.g. the width found
// on the neighbouring pyramid level, where the per-level target follows the level area and the
// width barely changes) ends the search after two or three passes. The bisection between the
// closed-form bounds finishes inside the bracket; the result depends on the hint only through
// which feasible width is found first.
SscResult ssc_select(const std::vector<cv::KeyPoint>& keypoints, int target, cv::Size size,
                     double tolerance_fraction = 0.001, double width_hint = 0);

struct SscCornersResult {
  FastCorners kept;  // strongest first
  double width = 0;
  int iterations = 0;
};

// The same selection on the compact layout (the extractor's path): for corners c,
// ssc_select(c, ...).kept lists the corners at ssc_select(c.keypoints(), ...).kept, in that order,
// with the same width and passes. Reads 5 bytes per candidate and scatters positions only.
// Corners must lie inside `size` (std::invalid_argument otherwise).
SscCornersResult ssc_select(const FastCorners& corners, int target, cv::Size size, double tolerance_fraction = 0.001,
                            double width_hint = 0);

// Indices of `keypoints` sorted by decreasing response, ties by index (a counting sort when the
// responses are small integers, as FAST scores are).
std::vector<int> order_by_response(const std::vector<cv::KeyPoint>& keypoints);

namespace detail {
// For tests: while alive, ssc_select on this thread uses the portable scan instead of AVX2
// (the results must be identical).
class PortableSscScope {
 public:
  PortableSscScope();
  ~PortableSscScope();
  PortableSscScope(const PortableSscScope&) = delete;
  PortableSscScope& operator=(const PortableSscScope&) = delete;

 private:
  bool previous_;
};
bool ssc_portable_only();
// The covering's cell of pixel coordinate x at width w, floor(2x / w), as the scans compute it
// (float arithmetic, exact for x < 2^21); exposed for an exhaustive test.
int ssc_cell(uint32_t x, int w);
}  // namespace detail

}  // namespace plslam::features
