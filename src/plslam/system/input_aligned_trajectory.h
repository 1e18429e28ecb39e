#pragma once
// A trajectory with exactly one pose per input frame, for formats that pair poses with the ground
// truth by line number (KITTI). Frames that have no tracked pose (skipped, before the map was
// initialised, lost, or not reached) still get a line, so every later line keeps its index; that
// line repeats the last tracked pose before it (the first tracked pose for frames before it: the
// camera is taken to stand still), and `untracked` lists it.
#include <cstddef>
#include <vector>

#include "plslam/core/types.h"
#include "plslam/tracking/tracker.h"

namespace plslam::system {

struct InputAlignedTrajectory {
  Trajectory poses;                     // poses[i] for input frame i, T_world_leftcam
  std::vector<std::size_t> untracked;   // input frames whose line is not a tracked pose
};

// `records` carry input indices as frame ids; `timestamps` has one entry per input frame. Empty
// when no record is tracked (there is no pose to write). Throws std::logic_error for a record
// whose id is outside the input.
InputAlignedTrajectory align_to_input(const std::vector<tracking::FrameRecord>& records,
                                      const std::vector<double>& timestamps);

}  // namespace plslam::system
