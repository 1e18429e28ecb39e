#pragma once
// A small 2D line chart drawn with OpenCV: axes with "nice" ticks, grid, labels, title, legend
// and optional equal aspect, so evaluation plots are readable without Python.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::eval {

struct LineStyle {
  cv::Scalar color{0, 0, 0};  // BGR
  int thickness = 2;
  bool dashed = false;
};

class Chart {
 public:
  void set_title(std::string title) { title_ = std::move(title); }
  void set_xlabel(std::string label) { xlabel_ = std::move(label); }
  void set_ylabel(std::string label) { ylabel_ = std::move(label); }
  // One metre on x is as long as one metre on y (for top views).
  void set_equal_aspect(bool on) { equal_aspect_ = on; }
  // Start the y axis at 0 (for error magnitudes).
  void set_y_from_zero(bool on) { y_from_zero_ = on; }

  void add_line(std::vector<cv::Point2d> points, LineStyle style, std::string label);
  void add_hline(double y, LineStyle style, std::string label);
  void add_marker(cv::Point2d p, cv::Scalar color, std::string label);

  // Draws into the whole of `canvas` (8-bit BGR; may be an ROI of a larger image).
  void draw(cv::Mat& canvas) const;

 private:
  struct Line {
    std::vector<cv::Point2d> points;
    LineStyle style;
    std::string label;
  };
  struct HLine {
    double y;
    LineStyle style;
    std::string label;
  };
  struct Marker {
    cv::Point2d p;
    cv::Scalar color;
    std::string label;
  };
  std::string title_, xlabel_, ylabel_;
  bool equal_aspect_ = false;
  bool y_from_zero_ = false;
  std::vector<Line> lines_;
  std::vector<HLine> hlines_;
  std::vector<Marker> markers_;
};

// Tick positions for [lo, hi]: multiples of 1, 2 or 5 x 10^k, about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

}  // namespace plslam::eval
