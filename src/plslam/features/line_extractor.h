#pragma once
// One call per image: detect -> merge -> keep best N -> describe (LBD). This is the unit the
// frame integration runs as one task per image, and what `plslam bench features` times.
#include <cstddef>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/line_descriptor.h"
#include "plslam/features/line_detector.h"
#include "plslam/features/line_merger.h"
#include "plslam/features/line_segment.h"

namespace plslam::features {

struct LineExtractorOptions {
  LineDetectorOptions detector;
  LineMergeOptions merge;
  bool merge_enabled = true;
  std::size_t max_lines = 200;  // 200 for EuRoC, 500 for KITTI
  // Drop lines flatter than this before keeping the best N (0: keep all). The SLAM front end sets
  // it to the stereo matcher's limit, since only stereo lines enter its optimisation.
  double min_angle_from_horizontal_deg = 0;
  LbdOptions lbd;

  static LineExtractorOptions euroc() { return {}; }
  static LineExtractorOptions kitti() {
    LineExtractorOptions o;
    o.max_lines = 500;
    return o;
  }
};

struct LineFeatures {
  std::vector<LineSegment> lines;  // longest first
  cv::Mat descriptors;             // lines.size() x 32, CV_8U (256-bit LBD)
  cv::Size image_size;
};

// Per-stage wall-clock (ms) and counts of one extraction.
struct LineTimings {
  double detect_ms = 0, merge_ms = 0, describe_ms = 0;
  std::size_t detected = 0, merged = 0, kept = 0;
  double total_ms() const { return detect_ms + merge_ms + describe_ms; }
};

LineFeatures extract_lines(const cv::Mat& grey, const LineExtractorOptions& options = {},
                           LineTimings* timings = nullptr);

}  // namespace plslam::features
