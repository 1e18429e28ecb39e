#pragma once
// Descriptor matching between two images guided by the vocabulary (ORB-SLAM2's SearchByBoW):
// a feature is compared only with the other image's features under the same vocabulary node, so
// a frame is matched to a keyframe without any pose, in a fraction of a brute-force search.
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/place/bow_vector.h"

namespace plslam::place {

struct BowMatchOptions {
  int max_hamming = 50;         // of 256 bits (ORB-SLAM2's TH_LOW: no pose to check the match)
  double ratio = 0.75;          // best < ratio * second best
  bool check_orientation = true;
  int orientation_bins = 30;    // histogram of keypoint rotation differences
};

struct BowMatch {
  int query = -1;  // feature index in the query image
  int train = -1;  // feature index in the other image
  int distance = 0;
};

struct BowImage {
  const cv::Mat* descriptors = nullptr;         // N x 32 CV_8U
  const FeatureVector* features = nullptr;      // of those descriptors
  const std::vector<cv::KeyPoint>* keypoints = nullptr;  // angles for the orientation check
};

// Each usable train feature (`train_usable`, null: all) is matched to the closest query feature in
// its node, under max_hamming and the ratio test; a query feature keeps only its closest train
// feature, and only when it passes the ratio test against the other train features that chose it. With check_orientation, only matches whose rotation difference falls in the three most
// populated bins (and in bins holding at least a tenth of the most populated) survive: one image
// is rotated against the other by one angle, so wrong matches scatter and true ones pile up.
// Sorted by train index.
std::vector<BowMatch> match_by_bow(const BowImage& query, const BowImage& train,
                                   const std::function<bool(int)>& train_usable = {},
                                   const BowMatchOptions& options = {});

// The indices of `angle_differences_deg` (each in any range) kept by the orientation check above.
std::vector<std::size_t> orientation_consistent(const std::vector<double>& angle_differences_deg, int bins);

}  // namespace plslam::place
