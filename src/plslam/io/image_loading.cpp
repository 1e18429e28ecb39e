#include "plslam/io/image_loading.h"

#include <cctype>
#include <fstream>
#include <initializer_list>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"
#include "plslam/io/png_grey.h"

namespace plslam::io {
namespace {

// Binary PGM/PPM (P5/P6) store their pixels raw: a header promising more pixels than the file holds
// is truncated, and OpenCV would first allocate the promised size (a 74-byte file claiming
// 99999 x 9199 pixels took a gigabyte and 11 s under ASan: found by fuzzing,
// tests/fuzz/corpus/image/pgm_giant_header_short_file). Returns the problem, or "" when fine.
std::string raw_pnm_size_problem(const std::vector<uchar>& bytes) {
  if (bytes.size() < 2 || bytes[0] != 'P' || (bytes[1] != '5' && bytes[1] != '6')) return "";
  std::size_t i = 2;
  long long values[3] = {0, 0, 0};
  for (long long& v : values) {
    while (i < bytes.size()) {  // whitespace and # comments
      if (bytes[i] == '#') {
        while (i < bytes.size() && bytes[i] != '\n') ++i;
      } else if (std::isspace(bytes[i])) {
        ++i;
      } else {
        break;
      }
    }
    if (i >= bytes.size() || !std::isdigit(bytes[i])) return "malformed PGM/PPM header";
    while (i < bytes.size() && std::isdigit(bytes[i]) && v < 1000000000) v = v * 10 + (bytes[i++] - '0');
  }
  ++i;  // the single whitespace after maxval
  const long long channels = bytes[1] == '6' ? 3 : 1, depth = values[2] > 255 ? 2 : 1;
  // In double: each value may be up to ~1e10, their product overflows any integer type (fuzzing).
  const double need = static_cast<double>(values[0]) * static_cast<double>(values[1]) * static_cast<double>(channels * depth);
  const double have = bytes.size() > i ? static_cast<double>(bytes.size() - i) : 0.0;
  if (need > have) return fmt::format("truncated PGM/PPM: the header says {} x {} pixels, the file holds {} bytes of them", values[0], values[1], have);
  return "";
}

// The formats the dataset readers take (kitti_dataset.cpp's extensions), told by the same
// signatures OpenCV's own decoders check, which it tries before any other: so cv::imdecode picks
// one of them. Otherwise it would try every codec OpenCV was built with, and GDCM asserts (aborts
// the process) on a damaged DICOM file, or allocates what its header says (4 GB): found by
// fuzzing, tests/fuzz/corpus/image/dicom_assert_in_gdcm and dicom_after_png_magic_4gb.
bool is_supported_format(const std::vector<uchar>& b) {
  auto starts = [&](std::initializer_list<int> magic) {
    if (b.size() < magic.size()) return false;
    std::size_t i = 0;
    for (const int m : magic)
      if (b[i++] != m) return false;
    return true;
  };
  return starts({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}) || starts({0xff, 0xd8, 0xff}) || starts({'B', 'M'}) ||
         starts({'I', 'I', 42, 0}) || starts({'M', 'M', 0, 42}) ||
         (b.size() >= 3 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6' && std::isspace(b[2]));  // PBM, PGM, PPM
}

}  // namespace

cv::Mat load_grey_image(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string(), "is a folder, expected an image file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path.string(), "image file not found");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path.string(), "cannot open image");
  // One read of the whole file: byte by byte through a stream iterator took 0.46 ms for a KITTI
  // PNG (0.07 ms so), next to 1.05 ms to decode it.
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path.string(), "cannot read image");
  std::vector<uchar> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), size))
    throw InputError(path.string(), "cannot read image");
  if (bytes.empty()) throw InputError(path.string(), "empty image file");
  // imdecode returns an empty Mat (and libpng may print a warning) for corrupt or truncated data.
  if (const auto problem = raw_pnm_size_problem(bytes); !problem.empty()) throw InputError(path.string(), problem);
  if (!is_supported_format(bytes))
    throw InputError(path.string(), "not a PNG, JPEG, PGM/PPM, BMP or TIFF image");
  if (auto grey = decode_grey8_png(bytes)) return std::move(*grey);
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
