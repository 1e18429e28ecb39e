#pragma once
// Calibration boards: a ChArUco board (a chessboard with ArUco markers in its white squares, so
// that corners are identified even where only part of the board is seen, as near a fisheye's
// rim) or a plain chessboard, which must be seen whole. Written as
//   charuco:COLSxROWS:SQUARE_M:MARKER_M[:DICTIONARY]   e.g. charuco:10x7:0.06:0.045:5x5_100
//   chessboard:COLSxROWS:SQUARE_M                      e.g. chessboard:9x7:0.05
// where COLS x ROWS counts squares (a chessboard of 9 x 7 squares has 8 x 6 inner corners).
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::calib {

enum class BoardKind { kCharuco, kChessboard };

struct BoardSpec {
  BoardKind kind = BoardKind::kCharuco;
  int cols = 10, rows = 7;  // squares
  double square_m = 0.06;
  double marker_m = 0.045;  // ChArUco only
  std::string dictionary = "5x5_100";  // ChArUco only: 4x4_50 ... 7x7_1000, as OpenCV's DICT_*

  int corner_count() const { return (cols - 1) * (rows - 1); }
  // The inner corners in the board's frame (metres, z = 0), indexed as the detector's ids: row
  // by row from the board's first corner, as OpenCV's CharucoBoard numbers them.
  std::vector<cv::Point3f> corners() const;
};

// Throws InputError naming `source` (the option) on a malformed spec.
BoardSpec parse_board_spec(const std::string& text, const std::string& source = "--board");
std::string to_string(const BoardSpec& spec);

// The board as an 8-bit image (black 0, white 255) of `px_per_square` pixels per square, without
// a margin, with the board's first corner at the image's top left.
cv::Mat draw_board(const BoardSpec& spec, int px_per_square);

// Corners found in one grey image: ids index BoardSpec::corners(), positions are sub-pixel.
struct BoardDetection {
  std::vector<int> ids;
  std::vector<cv::Point2f> pixels;
  int markers = 0;  // ChArUco markers decoded
};

// Finds the board's corners. A chessboard is found whole or not at all; a ChArUco board yields the
// corners next to at least two decoded markers. Nothing found gives an empty detection.
BoardDetection detect_board(const cv::Mat& grey, const BoardSpec& spec);

}  // namespace plslam::calib
