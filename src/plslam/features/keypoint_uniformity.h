#pragma once
// Spatial uniformity of a keypoint set: the coefficient of variation (std / mean) of the number
// of keypoints in the cells of a cols x rows grid over the image. 0 is perfectly even.
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::features {

double grid_count_cv(const std::vector<cv::KeyPoint>& keypoints, cv::Size image_size, int cols = 16, int rows = 12);

}  // namespace plslam::features
