#pragma once
// Stereo point matching for a rectified pair (ORB-SLAM2's scheme): for each left keypoint,
// right keypoints in a row band (scaled by the pyramid level) and in the disparity range
// [0, bf/z_min] compete by Hamming distance; the best one under a threshold is refined by SAD
// on an 11x11 window with an equiangular (V) sub-pixel fit (ORB-SLAM2 fits a parabola), and
// matches whose SAD is far above the median are rejected.
#include <vector>

#include "plslam/features/orb_extractor.h"

namespace plslam::matching {

struct StereoPointOptions {
  double bf = 0;             // baseline * fx, in metres*pixels; must be positive
  double min_depth = 0;      // z_min in metres; 0 means the baseline (ORB-SLAM2: d_max = fx)
  double baseline = 0;       // metres; used for min_depth = 0
  // ORB-SLAM2's TH_HIGH. Its stereo threshold is 75, but low-threshold FAST corners carry
  // noisier descriptors; the SAD check below catches the extra wrong matches (on synthetic scenes
  // 99 % of depths stay within 1 % either way; on KITTI 06 the share with depth rises ~6 points).
  int max_hamming = 100;
  float row_band = 2.0f;     // +- rows at level 0, times the level scale
  int sad_half_window = 5;   // 11x11
  int sad_search = 5;        // +- level pixels around the descriptor match
  // Reject SAD > factor * median. ORB-SLAM2 uses 1.5 * 1.4 on centre-subtracted SAD; the
  // zero-mean SAD used here spreads wider on real images, so the cut is looser.
  double sad_outlier_factor = 3.0;

  void validate() const;  // InputError on bad values
};

struct StereoPointMatches {
  // Per left keypoint: right image u (level-0 pixels) and depth in metres; -1 when unmatched.
  std::vector<float> u_right;
  std::vector<float> depth;
  int matched = 0;
  // Why the other left keypoints have no depth (diagnostics for tuning and the bench).
  struct Rejections {
    int no_candidate = 0;    // nothing in the row band, level range and disparity range
    int hamming = 0;         // best descriptor distance above max_hamming
    int window = 0;          // SAD window or search leaves the level image
    int sad_edge = 0;        // SAD minimum at the end of the search, or a bad parabola
    int disparity = 0;       // refined disparity outside [0, d_max)
    int sad_outlier = 0;     // SAD above factor * median
  } rejected;
};

StereoPointMatches match_stereo_points(const features::PointFeatures& left,
                                       const features::PointFeatures& right,
                                       const StereoPointOptions& options);

namespace detail {
// Which code computes the SAD curve: 16-bit lanes, one per shift, in AVX2 where the CPU has it
// (kAuto, what matching uses) or in the baseline SSE2 code (kSse2), for windows up to 11 x 11;
// or plain 32-bit code (kPlain, and any larger window). All give the same integers.
enum class SadCode { kAuto, kSse2, kPlain };

// The SAD curve match_stereo_points refines with: for each shift s in [-search, search], the sum
// over the (2 half_window + 1)^2 window at (xl, y) in `left` of |left - right(x + xr0 - xl + s) -
// offset_s|, where offset_s is the rounded difference of the two windows' means; into
// sad[s + search].
void zero_mean_sad_curve(const cv::Mat& left, int xl, int y, const cv::Mat& right, int xr0, int half_window,
                         int search, SadCode code, int* sad);
}  // namespace detail

}  // namespace plslam::matching
