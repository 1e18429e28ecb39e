#pragma once
// Descriptor helpers shared by points and lines (both 256-bit binary descriptors).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::map {

// Hamming distance of two 1x32 CV_8U rows (ORB and LBD descriptors are both 256 bits).
int descriptor_distance(const cv::Mat& a, const cv::Mat& b);

// Of 32-byte descriptor rows, the index of the first with the smallest median distance to all
// rows, itself included (ORB-SLAM2's choice of a landmark's representative descriptor); 0 for an
// empty input.
std::size_t most_distinctive_index(const std::vector<const uint8_t*>& rows);

}  // namespace plslam::map
