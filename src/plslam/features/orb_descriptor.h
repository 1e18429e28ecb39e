#pragma once
// Oriented FAST + rotated BRIEF pieces: intensity-centroid orientation and a 256-bit binary
// descriptor sampled with a pattern rotated by the keypoint angle.
#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::features {

inline constexpr int kOrbPatchRadius = 15;      // orientation patch: a disc of radius 15 (31x31)
inline constexpr int kOrbDescriptorBytes = 32;  // 256 bits
// Pattern coordinates stay within +-13 px, so a rotated sample is at most 13*sqrt(2) < 19 px
// from the keypoint.
inline constexpr int kBriefPatternHalfExtent = 13;

// 256 test pairs (x1, y1, x2, y2), drawn once from an isotropic Gaussian with sigma = 31/5
// (BRIEF's G II), clipped to +-13 px, by a fixed-seed generator: identical on every platform.
const std::array<std::array<int8_t, 4>, 256>& brief_pattern();

// Angle in degrees [0, 360) of the intensity centroid of the radius-15 disc around (x, y), in
// image axes (x right, y down). Reads rows y-15..y+15 and columns x-15..x+16 (one spare column
// for a fixed-width loop), which must lie inside `image`'s allocation.
float intensity_centroid_angle(const cv::Mat& image, int x, int y);

// Writes the 32-byte descriptor of the point (x, y) with orientation `angle_deg` sampled in
// `blurred`; bit j of byte i is set when sample 8i+j's first point is darker than its second.
void brief_descriptor(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out);

// Hamming distance between two 32-byte descriptors.
int hamming_distance(const uint8_t* a, const uint8_t* b);

namespace detail {
// The two above compiled for baseline x86-64 only; the public ones run an AVX2 build of the same
// code where the CPU has it. Both give the same results.
float intensity_centroid_angle_baseline(const cv::Mat& image, int x, int y);
void brief_descriptor_baseline(const cv::Mat& blurred, int x, int y, float angle_deg, uint8_t* out);
}  // namespace detail

}  // namespace plslam::features
