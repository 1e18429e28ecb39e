#pragma once
// One call for a rectified stereo pair: ORB extraction of the left and the right image in
// parallel, then stereo point matching.
#include <opencv2/core.hpp>

#include "plslam/features/orb_extractor.h"
#include "plslam/matching/stereo_point_matcher.h"

namespace plslam::matching {

struct StereoPointFrame {
  features::PointFeatures left, right;
  StereoPointMatches stereo;  // indexed like left.keypoints
  features::ExtractionTimings left_timings, right_timings;
  double extraction_wall_ms = 0;  // both images, concurrently
  double stereo_ms = 0;
};

// Right keypoints only serve stereo matching. The spatial selection of the two images picks
// partly different corners (the content shifts by the disparity under a fixed grid), so the right
// image keeps `factor` times more points to give each left point's counterpart a chance.
features::OrbOptions right_image_options(const features::OrbOptions& left, double factor = 2.0);

// `left_extractor` and `right_extractor` may be the same object.
StereoPointFrame extract_stereo_points(const features::OrbExtractor& left_extractor,
                                       const features::OrbExtractor& right_extractor, const cv::Mat& left,
                                       const cv::Mat& right, const StereoPointOptions& options);

}  // namespace plslam::matching
