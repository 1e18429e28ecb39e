#pragma once
// The paper's frame integration: points and lines of both images are extracted and matched in
// stereo concurrently, and assembled into one FrameData. It runs as two lanes, one per core of
// the 2-core target: the left lines, then the guided search for them along their rows in the
// right image; and the left points, the right points, then their stereo matching. Without guided
// lines, the right lines are a third task, matched after the join.
#include <memory>
#include <mutex>

#include <opencv2/core.hpp>

#include "plslam/core/types.h"
#include "plslam/core/worker_pool.h"
#include "plslam/features/line_extractor.h"
#include "plslam/features/orb_extractor.h"
#include "plslam/map/frame_data.h"
#include "plslam/matching/guided_stereo_lines.h"
#include "plslam/matching/stereo_line_matcher.h"
#include "plslam/matching/stereo_point_matcher.h"

namespace plslam::tracking {

struct FrameExtractorOptions {
  features::OrbOptions orb;
  double right_points_factor = 2.0;  // right image keeps this many times more points (stereo recall)
  matching::StereoPointOptions stereo_points;  // bf and baseline are filled from the calibration
  bool lines = true;
  features::LineExtractorOptions line_extractor;
  matching::StereoLineMatchOptions stereo_lines;
  // Right-image lines from a search along each left line's rows instead of a second detection:
  // 7-18 % less tracking time at the same median ATE (docs/analysis/timing.md).
  bool guided_stereo_lines = true;
  matching::GuidedStereoLineOptions guided_lines;

  static FrameExtractorOptions euroc();
  static FrameExtractorOptions kitti();
};

struct FrameTimings {
  double extraction_ms = 0;  // wall clock of the lanes, with the stereo point and guided line matching
  double stereo_ms = 0;      // wall clock of the matching after them (detected right lines only)
  double total_ms = 0;       // extraction + stereo + assembly
  features::ExtractionTimings left_points;
  features::LineTimings left_lines;
  double stereo_points_ms = 0, stereo_lines_ms = 0;
  int stereo_points = 0, stereo_lines = 0;
};

class FrameExtractor {
 public:
  FrameExtractor(const StereoCalibration& calib, FrameExtractorOptions options);

  // Safe to call from several threads; the calls take turns.
  std::shared_ptr<map::FrameData> extract(long frame_id, double timestamp, const cv::Mat& left,
                                          const cv::Mat& right, FrameTimings* timings = nullptr) const;

  const StereoCalibration& calibration() const { return calib_; }
  const FrameExtractorOptions& options() const { return options_; }

 private:
  StereoCalibration calib_;
  FrameExtractorOptions options_;
  features::OrbExtractor left_orb_;
  features::OrbExtractor right_orb_;
  std::unique_ptr<core::WorkerPool> lanes_;  // this thread and one waiting worker
  mutable std::mutex lanes_mutex_;
};

}  // namespace plslam::tracking
