#include "plslam/map/frame_data.h"

#include <algorithm>
#include <cmath>

namespace plslam::map {

optim::StereoPointObservation FrameData::point_observation(std::size_t i, double max_depth_baselines) const {
  optim::StereoPointObservation o;
  o.measurement = {keypoints[i].pt.x, keypoints[i].pt.y, u_right[i]};
  o.has_right = stereo_constraint(i, max_depth_baselines);
  o.level = keypoints[i].octave;
  return o;
}

void FrameData::build_grid() {
  constexpr std::size_t kCells = static_cast<std::size_t>(kGridCols * kGridRows);
  const double cw = static_cast<double>(calib.width) / kGridCols;
  const double ch = static_cast<double>(calib.height) / kGridRows;
  std::vector<int> cell(keypoints.size());
  grid_offsets.assign(kCells + 1, 0);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const int cx = std::clamp(static_cast<int>(keypoints[i].pt.x / cw), 0, kGridCols - 1);
    const int cy = std::clamp(static_cast<int>(keypoints[i].pt.y / ch), 0, kGridRows - 1);
    cell[i] = cy * kGridCols + cx;
    ++grid_offsets[static_cast<std::size_t>(cell[i]) + 1];
  }
  for (std::size_t c = 0; c < kCells; ++c) grid_offsets[c + 1] += grid_offsets[c];
  grid_indices.resize(keypoints.size());
  std::vector<int> next(grid_offsets.begin(), grid_offsets.end() - 1);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    grid_indices[static_cast<std::size_t>(next[static_cast<std::size_t>(cell[i])]++)] = static_cast<int>(i);
  }
}

std::vector<int> FrameData::points_in_area(double u, double v, double r, int min_level, int max_level) const {
  std::vector<int> out;
  if (!has_grid()) return out;
  const double cw = static_cast<double>(calib.width) / kGridCols;
  const double ch = static_cast<double>(calib.height) / kGridRows;
  const int x0 = std::max(0, static_cast<int>(std::floor((u - r) / cw)));
  const int x1 = std::min(kGridCols - 1, static_cast<int>(std::floor((u + r) / cw)));
  const int y0 = std::max(0, static_cast<int>(std::floor((v - r) / ch)));
  const int y1 = std::min(kGridRows - 1, static_cast<int>(std::floor((v + r) / ch)));
  if (x0 > x1 || y0 > y1) return out;
  const double r2 = r * r;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const auto c = static_cast<std::size_t>(y * kGridCols + x);
      for (int k = grid_offsets[c]; k < grid_offsets[c + 1]; ++k) {
        const int i = grid_indices[static_cast<std::size_t>(k)];
        const auto& kp = keypoints[static_cast<std::size_t>(i)];
        if (kp.octave < min_level || (max_level >= 0 && kp.octave > max_level)) continue;
        const double dx = kp.pt.x - u, dy = kp.pt.y - v;
        if (dx * dx + dy * dy <= r2) out.push_back(i);
      }
    }
  }
  return out;
}

// Products instead of std::pow: these sit in the inner loops of matching and triangulation, and
// levels are small non-negative integers.
double FrameData::level_scale(int level) const {
  double s = 1.0;
  for (int l = 0; l < level; ++l) s *= scale_factor;
  return s;
}
double FrameData::level_sigma2(int level) const {
  const double s = level_scale(level);
  return s * s;
}

}  // namespace plslam::map
