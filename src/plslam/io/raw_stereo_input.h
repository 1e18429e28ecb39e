#pragma once
// Raw (not rectified) stereo pairs in order, for calibration: an EuRoC-layout folder (mav0/cam0
// and mav0/cam1 with data.csv), two folders of images, a side-by-side video, or two videos. Pairs
// must be synchronised; inputs that show they are not are refused.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace plslam::io {

struct RawStereoInputSpec {
  std::filesystem::path folder;               // EuRoC layout (<seq> or <seq>/mav0)
  std::filesystem::path left_dir, right_dir;  // image folders, paired by file name
  std::filesystem::path video;                // side by side (left | right), or the left camera's
  std::filesystem::path video_right;          // the right camera's, with `video`
};

struct RawStereoPair {
  std::size_t index = 0;  // 0-based, in input order
  std::string label;      // the left image's file name, or "frame N" of a video
  cv::Mat left, right;    // 8-bit grey, of one size
};

class RawStereoInput {
 public:
  virtual ~RawStereoInput() = default;
  // Pairs in the input (a video's count from its header).
  virtual std::size_t size() const = 0;
  // The next pair, or nullopt at the end. Throws InputError naming the file on an image that does
  // not decode or does not have the first pair's size.
  virtual std::optional<RawStereoPair> next() = 0;
  virtual std::string name() const = 0;
};

// Exactly one form of `spec` is set. Throws InputError naming the file or folder when it is
// missing or empty, and for unsynchronised pairs: EuRoC stamps more than 1 ms apart for over a
// tenth of the images, image folders of different counts or whose names differ pair by pair (equal
// names, or nanosecond stamps within 1 ms, make a pair), or two videos of different frame counts
// or rates.
std::unique_ptr<RawStereoInput> open_raw_stereo_input(const RawStereoInputSpec& spec);

}  // namespace plslam::io
