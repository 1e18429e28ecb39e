#include "plslam/matching/stereo_point_frame.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <future>

namespace plslam::matching {

features::OrbOptions right_image_options(const features::OrbOptions& left, double factor) {
  features::OrbOptions right = left;
  right.n_features = std::max(1, static_cast<int>(std::lround(left.n_features * factor)));
  return right;
}

StereoPointFrame extract_stereo_points(const features::OrbExtractor& left_extractor,
                                       const features::OrbExtractor& right_extractor, const cv::Mat& left,
                                       const cv::Mat& right, const StereoPointOptions& options) {
  using Clock = std::chrono::steady_clock;
  options.validate();
  StereoPointFrame f;
  auto t0 = Clock::now();
  {
    // A plain thread, as in tracking::FrameExtractor: its join is a synchronisation
    // ThreadSanitizer can see, where TBB's happens inside the uninstrumented libtbb.
    auto right_task = std::async(std::launch::async, [&] { f.right = right_extractor.extract(right, &f.right_timings); });
    f.left = left_extractor.extract(left, &f.left_timings);
    right_task.get();
  }
  auto t1 = Clock::now();
  f.stereo = match_stereo_points(f.left, f.right, options);
  auto t2 = Clock::now();
  f.extraction_wall_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  f.stereo_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  return f;
}

}  // namespace plslam::matching
