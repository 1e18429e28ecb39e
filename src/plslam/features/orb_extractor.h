#pragma once
// ORB extraction for one image: pyramid -> FAST per level -> spatial distribution (SSC or
// ORB-SLAM2's quadtree) -> orientation and rotated BRIEF on the kept points only.
// extract() is const and keeps no state, so one extractor can serve the left and the right
// image from two threads at once.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/features/fast_detector.h"
#include "plslam/features/image_pyramid.h"

namespace plslam::features {

enum class Distribution { kSsc, kQuadtree };
enum class FastMode {
  kSingle,  // one threshold over each whole level (the paper: 7)
  kIniMin,  // ORB-SLAM2: per 30 px cell the initial threshold, the minimum one if the cell is empty
};

const char* to_string(Distribution d);
Distribution parse_distribution(const std::string& name);  // ssc|quadtree, else InputError
const char* to_string(FastMode m);
FastMode parse_fast_mode(const std::string& name);  // single|ini_min, else InputError

struct OrbOptions {
  int n_features = 1200;  // over all levels, shared in proportion to each level's area
  int levels = 8;
  double scale_factor = 1.2;
  FastMode fast_mode = FastMode::kSingle;
  int fast_threshold = 7;       // kSingle
  int fast_ini_threshold = 20;  // kIniMin
  int fast_min_threshold = 7;   // kIniMin
  FastImpl fast_impl = FastImpl::kAuto;  // same corners whichever; kOpenCv for comparisons
  Distribution distribution = Distribution::kSsc;
  double ssc_tolerance = 0.001;  // fraction of the per-level target (the paper's 0.001 N)
  int edge_margin = 16;          // keypoints stay this far inside each level (pixels of that level)

  static OrbOptions euroc() { return {}; }
  static OrbOptions kitti() {
    OrbOptions o;
    o.n_features = 2000;
    return o;
  }
  // Throws InputError naming the bad field.
  void validate() const;
};

// Milliseconds per stage of one extract() call.
struct ExtractionTimings {
  double pyramid_ms = 0, fast_ms = 0, distribution_ms = 0, orb_ms = 0;
  int fast_candidates = 0;
  double total_ms() const { return pyramid_ms + fast_ms + distribution_ms + orb_ms; }
};

struct PointFeatures {
  // Level-0 pixel coordinates; octave = pyramid level, angle in degrees, size = 31 * scale^level,
  // response = FAST score.
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;   // keypoints.size() x 32, CV_8U
  ImagePyramid pyramid;  // unblurred levels, for stereo refinement and later patch work
};

// FAST corners of one level, in coordinates relative to `offset` within the level image and
// inside [0, region.width) x [0, region.height), in the compact layout both distributions read.
struct LevelCandidates {
  cv::Point offset;
  cv::Size region;
  FastCorners corners;
};
using PyramidCandidates = std::vector<LevelCandidates>;

class OrbExtractor {
 public:
  explicit OrbExtractor(OrbOptions options = {});
  const OrbOptions& options() const { return options_; }

  // `image`: 8-bit grey. Timings are written when `timings` is not null.
  PointFeatures extract(const cv::Mat& image, ExtractionTimings* timings = nullptr) const;

  // The stages extract() runs, public for benchmarks and tests.
  void build_pyramid(const cv::Mat& image, ImagePyramid& pyramid) const;
  PyramidCandidates detect(const ImagePyramid& pyramid) const;
  // Per-level targets: n_features in proportion to level area, a level's shortfall of
  // candidates handed on to the other levels.
  std::vector<int> level_targets(const PyramidCandidates& candidates) const;
  // Keeps the distributed subset of each level (strongest first).
  PyramidCandidates distribute(const PyramidCandidates& candidates, Distribution method) const;
  // Orientation, blur and descriptors of the kept points; fills out.keypoints/descriptors.
  void describe(const ImagePyramid& pyramid, const PyramidCandidates& kept, PointFeatures& out) const;

 private:
  OrbOptions options_;
};

}  // namespace plslam::features
