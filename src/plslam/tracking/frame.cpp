#include "plslam/tracking/frame.h"

#include <algorithm>

#include "plslam/map/map_line.h"
#include "plslam/map/map_point.h"

namespace plslam::tracking {

// Culled landmarks do not count: whether reclamation has cleared them from the frame yet depends on
// when it ran, which the count must not.
int Frame::num_matched_points() const {
  int n = 0;
  for (std::size_t i = 0; i < points.size(); ++i) n += points[i] && !point_outlier[i] && !points[i]->is_bad();
  return n;
}

int Frame::num_matched_lines() const {
  int n = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) n += lines[i] && !line_outlier[i] && !lines[i]->is_bad();
  return n;
}

int Frame::num_stereo_points() const {
  int n = 0;
  for (const float z : data->depth) n += z > 0;
  return n;
}

void Frame::clear_matches() {
  std::fill(points.begin(), points.end(), nullptr);
  std::fill(lines.begin(), lines.end(), nullptr);
}

void Frame::discard_outliers() {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (point_outlier[i]) {
      points[i] = nullptr;
      point_outlier[i] = false;
    }
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (line_outlier[i]) {
      lines[i] = nullptr;
      line_outlier[i] = false;
    }
  }
}

}  // namespace plslam::tracking
