#pragma once
// Our own binary LBD (Zhang & Koch 2013): the line support region is m bands of w rows parallel
// to the segment; each row sums the gradient's positive and negative parts across and along the
// line (global Gaussian weight by distance to the line), each band takes the weighted mean and
// std of the rows of itself and its neighbours (local Gaussian), giving 8 floats per band. The
// 256 bits compare those band vectors pairwise, nearest band pairs first, as OpenCV's binary
// LBD does. It samples the detector's shared gradient, at most `max_samples_along` times
// along the line, which bounds the cost of long lines.
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/line_gradient.h"
#include "plslam/features/line_segment.h"

namespace plslam::features {

constexpr int kLbdBytes = 32;  // 256 bits

struct LbdOptions {
  int bands = 9;               // m
  int band_width = 5;          // w, rows of the working image (10 full-resolution px at scale 1/2)
  int max_samples_along = 12;  // samples along the segment per row
};

// One row of 32 bytes (CV_8U) per segment, in the order of `segments`.
cv::Mat describe_lines(const LineGradient& gradient, const std::vector<LineSegment>& segments,
                       const LbdOptions& options = {});

// The 72 (for m = 9) normalised floats before binarisation, one row per segment (CV_32F).
cv::Mat describe_lines_float(const LineGradient& gradient, const std::vector<LineSegment>& segments,
                             const LbdOptions& options = {});

namespace detail {
// Sums over `count` samples (a multiple of 4) of the positive and negative parts of the gradient
// across the line (dp = g . n) and along it (dl = g . d): sums = (dp+, dp-, dl+, dl-). The second
// is the portable code the first falls back to without SSE2; both give the same floats.
void positive_negative_sums(const float* gx, const float* gy, int count, cv::Point2f n, cv::Point2f d, float sums[4]);
void positive_negative_sums_portable(const float* gx, const float* gy, int count, cv::Point2f n, cv::Point2f d,
                                     float sums[4]);
}  // namespace detail

}  // namespace plslam::features
