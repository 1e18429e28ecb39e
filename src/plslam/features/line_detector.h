#pragma once
// Line segment detection on one grey image. Two selectable detectors:
//  - kLsd: OpenCV imgproc LSD (the reference; slow, ~25 ms per EuRoC image here).
//  - kGrow: our own LSD-style region growing on gradient orientation, on a downscaled image and
//    without LSD's NFA test (validated by length and rectangle density instead). It shares its
//    Sobel gradient with the LBD descriptor, so describing costs no second gradient pass.
// Both return segments in full-resolution pixels, oriented with the brighter side on the right.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/line_gradient.h"
#include "plslam/features/line_segment.h"

namespace plslam::features {

enum class LineDetectorKind { kLsd, kGrow };

const char* to_string(LineDetectorKind k);
LineDetectorKind parse_line_detector(const std::string& name);  // "lsd" | "grow"; throws InputError

struct LineDetectorOptions {
  LineDetectorKind kind = LineDetectorKind::kGrow;
  double scale = 0.5;          // working scale of the image (both detectors and the gradient)
  double min_length_px = 14;   // full-resolution pixels
  // kGrow
  float min_gradient = 32;         // Sobel magnitude (4x intensity step) a pixel needs to join
  float angle_tolerance_deg = 22.5;  // region growing: gradient within this of the region's
  float min_density = 0.4;         // region pixels / rectangle area, after trimming
  float max_half_width = 2.0;      // working pixels kept either side of the fitted line
  // kLsd (OpenCV parameters; LSD's own internal Gaussian scale, applied after `scale`)
  double lsd_internal_scale = 0.8;
  int lsd_refine = 0;  // cv::LSD_REFINE_NONE
};

struct DetectedLines {
  std::vector<LineSegment> segments;
  LineGradient gradient;  // at options.scale, reusable by describe_lines()
};

// Throws std::invalid_argument for an empty or non-8-bit image.
DetectedLines detect_lines(const cv::Mat& grey, const LineDetectorOptions& options = {});

// Region growing alone on a precomputed gradient (exposed for tests and benchmarks).
std::vector<LineSegment> grow_line_segments(const LineGradient& gradient, const LineDetectorOptions& options);

// Flips segments so that the mean gradient points to their right (brighter side right).
void orient_by_gradient(std::vector<LineSegment>& segments, const LineGradient& gradient);

}  // namespace plslam::features
