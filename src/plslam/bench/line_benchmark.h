#pragma once
// Measures the line front end on real frames, stage by stage, for `plslam bench features`:
// OpenCV LSD (reference) vs our region-growing detector, merging, our LBD, OpenCV's LBD on
// the same kept lines (for the ratio), and stereo matching. Runs on the calling thread.
#include <cstddef>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/line_descriptor.hpp>

#include "plslam/core/types.h"
#include "plslam/features/line_extractor.h"
#include "plslam/io/dataset.h"
#include "plslam/matching/stereo_line_matcher.h"

namespace plslam::bench {

struct LineBenchmarkOptions {
  features::LineExtractorOptions extractor;  // kind is forced to kGrow for the fast path
  matching::StereoLineMatchOptions stereo;
  bool reference = true;  // also time OpenCV LSD (full resolution) and OpenCV LBD
  // Polled before loading each frame after the first: true measures only the frames loaded so far.
  std::function<bool()> stop;
};

// Keys (each {median, p90} over frames): lsd_ms, fast_lines_ms, merge_ms, lbd_ms,
// lines_image_ms (detect+merge+describe, one image), opencv_lbd_ms, stereo_lines_ms,
// lines_detected, lines_after_merge, lines_kept, stereo_line_matches; plus frames and
// lines_speedup_vs_opencv (median OpenCV LSD + LBD over median lines_image_ms).
// Our segments as OpenCV KeyLines (octave 0), to run OpenCV's LBD on exactly the same lines.
std::vector<cv::line_descriptor::KeyLine> to_keylines(const std::vector<features::LineSegment>& lines,
                                                      cv::Size image_size);

nlohmann::json benchmark_lines(const std::vector<std::pair<cv::Mat, cv::Mat>>& stereo_frames,
                               const StereoCalibration& calib, const LineBenchmarkOptions& options = {});

// Loads frames [0, frames) (or all when frames is 0) and runs the above.
nlohmann::json benchmark_lines(const io::Dataset& dataset, std::size_t frames,
                               const LineBenchmarkOptions& options = {});

}  // namespace plslam::bench
