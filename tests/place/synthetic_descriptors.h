#pragma once
// Random 256-bit descriptors and noisy copies of them, for tests of the vocabulary, the keyframe
// database and BoW matching: the true word or match of each descriptor is known.
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/place/descriptor256.h"

namespace plslam::place {

inline Descriptor256 random_descriptor(std::mt19937_64& rng) { return {rng(), rng(), rng(), rng()}; }

// `d` with `bits` random bits flipped (a bit may flip twice).
inline Descriptor256 flip_bits(Descriptor256 d, int bits, std::mt19937_64& rng) {
  for (int i = 0; i < bits; ++i) {
    const auto b = rng() % 256;
    d[b / 64] ^= std::uint64_t{1} << (b % 64);
  }
  return d;
}

// Descriptors as the N x 32 CV_8U rows that frames and keyframes hold.
inline cv::Mat to_mat(const std::vector<Descriptor256>& ds) {
  cv::Mat m(static_cast<int>(ds.size()), 32, CV_8U);
  for (std::size_t i = 0; i < ds.size(); ++i) std::memcpy(m.ptr(static_cast<int>(i)), ds[i].data(), 32);
  return m;
}

}  // namespace plslam::place
