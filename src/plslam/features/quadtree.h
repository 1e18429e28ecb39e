#pragma once
// ORB-SLAM2's quadtree distribution (DistributeOctTree), the baseline SSC is compared against:
// the image is split into nodes, nodes holding more than one keypoint are split in four until
// there are at least N nodes, and each node keeps its strongest keypoint.
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/fast_detector.h"

namespace plslam::features {

// Returns indices of the kept keypoints, strongest first. Points lie in [0, size.width) x
// [0, size.height). ORB-SLAM2 may end with a few more than `target` nodes; those extra points
// are cut (weakest first) so both distributions return the same count.
std::vector<int> quadtree_select(const std::vector<cv::KeyPoint>& keypoints, int target, cv::Size size);
// The same on the compact layout (the distributions' input in the extractor): identical indices
// for the same corners.
std::vector<int> quadtree_select(const FastCorners& corners, int target, cv::Size size);

}  // namespace plslam::features
