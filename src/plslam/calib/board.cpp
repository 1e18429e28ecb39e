#include "plslam/calib/board.h"

#include <charconv>
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"

namespace plslam::calib {
namespace {

struct NamedDictionary {
  const char* name;
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
};

constexpr NamedDictionary kDictionaries[] = {
    {"4x4_50", cv::aruco::DICT_4X4_50},     {"4x4_100", cv::aruco::DICT_4X4_100},   {"4x4_250", cv::aruco::DICT_4X4_250},
    {"4x4_1000", cv::aruco::DICT_4X4_1000}, {"5x5_50", cv::aruco::DICT_5X5_50},     {"5x5_100", cv::aruco::DICT_5X5_100},
    {"5x5_250", cv::aruco::DICT_5X5_250},   {"5x5_1000", cv::aruco::DICT_5X5_1000}, {"6x6_50", cv::aruco::DICT_6X6_50},
    {"6x6_100", cv::aruco::DICT_6X6_100},   {"6x6_250", cv::aruco::DICT_6X6_250},   {"6x6_1000", cv::aruco::DICT_6X6_1000},
    {"7x7_50", cv::aruco::DICT_7X7_50},     {"7x7_100", cv::aruco::DICT_7X7_100},   {"7x7_250", cv::aruco::DICT_7X7_250},
    {"7x7_1000", cv::aruco::DICT_7X7_1000}};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::size_t begin = 0;
  while (true) {
    const auto end = s.find(sep, begin);
    parts.push_back(s.substr(begin, end - begin));
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

double parse_length(const std::string& text, const std::string& what, const std::string& source) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size() || !(v > 0 && v < 10)) {
    throw InputError(source, fmt::format("{} must be a length in metres in (0, 10), got '{}'", what, text));
  }
  return v;
}

cv::Ptr<cv::aruco::CharucoBoard> charuco_board(const BoardSpec& spec) {
  for (const auto& d : kDictionaries) {
    if (spec.dictionary == d.name) {
      return cv::aruco::CharucoBoard::create(spec.cols, spec.rows, static_cast<float>(spec.square_m),
                                             static_cast<float>(spec.marker_m), cv::aruco::getPredefinedDictionary(d.id));
    }
  }
  throw InputError("--board", "unknown ArUco dictionary '" + spec.dictionary + "'");
}

// OpenCV 4.6's interpolateCornersCharuco returns corners half a pixel off (+0.5, +0.5 on a drawn
// board, measured in tests/calib), so they are refined again here. Each corner's window stays
// well inside its squares: the markers' edges, an eighth of a square away, would pull it.
void refine_corners(const cv::Mat& grey, std::vector<cv::Point2f>& pixels) {
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    double nearest = 1e9;
    for (std::size_t j = 0; j < pixels.size(); ++j) {
      if (j != i) nearest = std::min(nearest, static_cast<double>(cv::norm(pixels[i] - pixels[j])));
    }
    const int half = std::clamp(static_cast<int>(0.1 * nearest), 2, 6);
    std::vector<cv::Point2f> one{pixels[i]};
    cv::cornerSubPix(grey, one, cv::Size(half, half), cv::Size(-1, -1), criteria);
    pixels[i] = one[0];
  }
}

}  // namespace

std::vector<cv::Point3f> BoardSpec::corners() const {
  if (kind == BoardKind::kCharuco) return charuco_board(*this)->chessboardCorners;  // OpenCV's numbering
  std::vector<cv::Point3f> out;
  for (int r = 1; r < rows; ++r)
    for (int c = 1; c < cols; ++c)
      out.emplace_back(static_cast<float>(c * square_m), static_cast<float>(r * square_m), 0.0f);
  return out;
}

BoardSpec parse_board_spec(const std::string& text, const std::string& source) {
  const auto parts = split(text, ':');
  BoardSpec spec;
  const std::string usage = "expected charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICT] or chessboard:COLSxROWS:SQUARE_M";
  if (parts[0] == "charuco" && (parts.size() == 4 || parts.size() == 5)) {
    spec.kind = BoardKind::kCharuco;
  } else if (parts[0] == "chessboard" && parts.size() == 3) {
    spec.kind = BoardKind::kChessboard;
  } else {
    throw InputError(source, fmt::format("bad board '{}': {}", text, usage));
  }
  const auto size = split(parts[1], 'x');
  int dims[2] = {0, 0};
  for (int k = 0; k < 2 && size.size() == 2; ++k) {
    const auto [ptr, ec] = std::from_chars(size[k].data(), size[k].data() + size[k].size(), dims[k]);
    if (ec != std::errc() || ptr != size[k].data() + size[k].size()) dims[k] = 0;
  }
  if (!(dims[0] >= 3 && dims[1] >= 3 && dims[0] <= 100 && dims[1] <= 100)) {
    throw InputError(source, fmt::format("bad board size '{}': COLSxROWS squares, each in [3, 100]", parts[1]));
  }
  spec.cols = dims[0];
  spec.rows = dims[1];
  spec.square_m = parse_length(parts[2], "the square size", source);
  if (spec.kind == BoardKind::kCharuco) {
    spec.marker_m = parse_length(parts[3], "the marker size", source);
    if (!(spec.marker_m < spec.square_m)) {
      throw InputError(source, fmt::format("the marker ({} m) must be smaller than the square ({} m)", spec.marker_m,
                                           spec.square_m));
    }
    if (parts.size() == 5) spec.dictionary = parts[4];
    const auto board = charuco_board(spec);  // checks the dictionary
    const int markers = (spec.cols * spec.rows) / 2;
    if (markers > static_cast<int>(board->dictionary->bytesList.rows)) {
      throw InputError(source, fmt::format("a {}x{} board needs {} markers, more than dictionary {} has", spec.cols,
                                           spec.rows, markers, spec.dictionary));
    }
  }
  return spec;
}

std::string to_string(const BoardSpec& spec) {
  if (spec.kind == BoardKind::kChessboard) return fmt::format("chessboard:{}x{}:{}", spec.cols, spec.rows, spec.square_m);
  return fmt::format("charuco:{}x{}:{}:{}:{}", spec.cols, spec.rows, spec.square_m, spec.marker_m, spec.dictionary);
}

cv::Mat draw_board(const BoardSpec& spec, int px_per_square) {
  const cv::Size size(spec.cols * px_per_square, spec.rows * px_per_square);
  cv::Mat img;
  if (spec.kind == BoardKind::kCharuco) {
    charuco_board(spec)->draw(size, img, 0, 1);
    return img;
  }
  img.create(size, CV_8U);
  for (int r = 0; r < spec.rows; ++r)
    for (int c = 0; c < spec.cols; ++c)
      img(cv::Rect(c * px_per_square, r * px_per_square, px_per_square, px_per_square)).setTo((r + c) % 2 ? 255 : 0);
  return img;
}

BoardDetection detect_board(const cv::Mat& grey, const BoardSpec& spec) {
  BoardDetection out;
  if (spec.kind == BoardKind::kChessboard) {
    std::vector<cv::Point2f> pixels;
    if (cv::findChessboardCornersSB(grey, cv::Size(spec.cols - 1, spec.rows - 1), pixels,
                                    cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) {
      out.pixels = pixels;
      for (int i = 0; i < static_cast<int>(pixels.size()); ++i) out.ids.push_back(i);
    }
    return out;
  }
  const auto board = charuco_board(spec);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  const auto params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;  // the chessboard corners are refined instead
  cv::aruco::detectMarkers(grey, board->dictionary, marker_corners, marker_ids, params);
  out.markers = static_cast<int>(marker_ids.size());
  if (marker_ids.empty()) return out;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, board, out.pixels, out.ids);
  refine_corners(grey, out.pixels);
  return out;
}

}  // namespace plslam::calib
