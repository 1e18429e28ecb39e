#pragma once
// A 256-bit binary descriptor (ORB, as plslam's extractor writes it) held as four 64-bit words,
// so the Hamming distance is four popcounts: the vocabulary compares every descriptor of a frame
// with a few dozen cluster centres.
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::place {

using Descriptor256 = std::array<std::uint64_t, 4>;

inline int hamming(const Descriptor256& a, const Descriptor256& b) {
  return std::popcount(a[0] ^ b[0]) + std::popcount(a[1] ^ b[1]) + std::popcount(a[2] ^ b[2]) +
         std::popcount(a[3] ^ b[3]);
}

// Row `row` of an N x 32 CV_8U matrix, bytes in memory order.
inline Descriptor256 descriptor_from_row(const cv::Mat& descriptors, int row) {
  Descriptor256 d;
  std::memcpy(d.data(), descriptors.ptr<std::uint8_t>(row), sizeof(d));
  return d;
}

// Every row of an N x 32 CV_8U matrix; throws std::invalid_argument for another shape or type.
std::vector<Descriptor256> descriptors_from_mat(const cv::Mat& descriptors);

}  // namespace plslam::place
