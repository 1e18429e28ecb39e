#include "plslam/tracking/frame.h"

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
