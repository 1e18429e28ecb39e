#pragma once
// Aligning an estimate to the ground truth before APE, as evo's --align / --correct_scale.
#include <string>

#include "plslam/core/types.h"
#include "plslam/geometry/umeyama.h"

namespace plslam::eval {

enum class AlignMode { kNone, kSE3, kSim3 };

const char* to_string(AlignMode mode);
// "none", "se3" or "sim3"; throws InputError otherwise.
AlignMode parse_align_mode(const std::string& name);

// The transform taking the estimate's positions onto the ground truth's (paired, equally long).
// kNone gives the identity. Throws InputError when the positions are degenerate.
geometry::AlignmentResult solve_alignment(const Trajectory& gt, const Trajectory& est, AlignMode mode);

// Applies it as evo does: positions p -> s R p + t, orientations R_p -> R R_p (the scale acts on
// positions only, so the poses stay rigid).
Trajectory apply_alignment(const Trajectory& est, const geometry::AlignmentResult& a);

}  // namespace plslam::eval
