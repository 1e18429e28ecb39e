#pragma once
// Absolute pose error, translation part: ||p_est,i - p_gt,i|| per pair (evo's APE with
// PoseRelation.translation_part), in the units of the ground truth.
#include <vector>

#include "plslam/core/types.h"

namespace plslam::eval {

// gt and est are paired pose by pose (same length) and est is already aligned.
std::vector<double> ape_translation(const Trajectory& gt, const Trajectory& est);

}  // namespace plslam::eval
