#include "plslam/io/image_loading.h"

#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"

namespace plslam::io {

cv::Mat load_grey_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path.string(), "image file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open image");
  const std::vector<uchar> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw InputError(path.string(), "empty image file");
  // imdecode returns an empty Mat (and libpng may print a warning) for corrupt or truncated data.
  cv::Mat img;
  try {
    img = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    // OpenCV asserts on headers it refuses, e.g. a PGM claiming 99999 x 99999 pixels (found by
    // fuzzing, tests/fuzz/corpus/image/pgm_huge_header): still bad input, not an internal error.
    throw InputError(path.string(), "undecodable image header (" + e.err + ")");
  }
  if (img.empty()) throw InputError(path.string(), "corrupt or truncated image");
  if (img.depth() != CV_8U) throw InputError(path.string(), "expected an 8-bit image");
  if (img.channels() == 3) {
    cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
  } else if (img.channels() == 4) {
    cv::cvtColor(img, img, cv::COLOR_BGRA2GRAY);
  } else if (img.channels() != 1) {
    throw InputError(path.string(), "unsupported channel count");
  }
  return img;
}

std::string blank_image_problem(const cv::Mat& image, const std::filesystem::path& path) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(image, &lo, &hi);
  return lo == hi ? fmt::format("{}: blank image (every pixel is {})", path.string(), lo) : std::string();
}

}  // namespace plslam::io
