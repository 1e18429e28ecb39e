#include "plslam/system/input_aligned_trajectory.h"

#include <optional>
#include <stdexcept>

namespace plslam::system {

InputAlignedTrajectory align_to_input(const std::vector<tracking::FrameRecord>& records,
                                      const std::vector<double>& timestamps) {
  std::vector<std::optional<Eigen::Isometry3d>> tracked(timestamps.size());
  bool any = false;
  for (const auto& rec : records) {
    if (rec.frame_id < 0 || static_cast<std::size_t>(rec.frame_id) >= timestamps.size()) {
      throw std::logic_error("align_to_input: frame id outside the input");
    }
    if (!rec.trusted()) continue;
    tracked[static_cast<std::size_t>(rec.frame_id)] = tracking::Tracker::pose_of(rec).inverse().isometry();
    any = true;
  }
  InputAlignedTrajectory out;
  if (!any) return out;
  std::optional<Eigen::Isometry3d> held;
  for (const auto& pose : tracked) {
    if (pose) {
      held = pose;
      break;
    }
  }
  for (std::size_t i = 0; i < timestamps.size(); ++i) {
    if (tracked[i]) {
      held = tracked[i];
    } else {
      out.untracked.push_back(i);
    }
    out.poses.push_back({timestamps[i], *held});
  }
  return out;
}

}  // namespace plslam::system
