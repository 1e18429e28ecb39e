#include "plslam/eval/alignment.h"

#include <stdexcept>

#include "plslam/core/error.h"

namespace plslam::eval {

const char* to_string(AlignMode mode) {
  switch (mode) {
    case AlignMode::kNone: return "none";
    case AlignMode::kSE3: return "se3";
    case AlignMode::kSim3: return "sim3";
  }
  return "?";
}

AlignMode parse_align_mode(const std::string& name) {
  if (name == "none") return AlignMode::kNone;
  if (name == "se3") return AlignMode::kSE3;
  if (name == "sim3") return AlignMode::kSim3;
  throw InputError("", "unknown alignment '" + name + "' (expected se3, sim3 or none)");
}

geometry::AlignmentResult solve_alignment(const Trajectory& gt, const Trajectory& est, AlignMode mode) {
  if (mode == AlignMode::kNone) return {};
  if (gt.size() != est.size()) throw std::invalid_argument("solve_alignment: unpaired trajectories");
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(est.size()));
  Eigen::Matrix3Xd dst(3, static_cast<Eigen::Index>(gt.size()));
  for (std::size_t i = 0; i < est.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = est[i].T.translation();
    dst.col(static_cast<Eigen::Index>(i)) = gt[i].T.translation();
  }
  try {
    return geometry::umeyama(src, dst, mode == AlignMode::kSim3);
  } catch (const std::invalid_argument& e) {
    throw InputError("", std::string("cannot align the estimate: ") + e.what());
  }
}

Trajectory apply_alignment(const Trajectory& est, const geometry::AlignmentResult& a) {
  Trajectory out = est;
  for (auto& p : out) {
    p.T.translation() = a.apply(p.T.translation());
    p.T.linear() = a.R * p.T.linear();
  }
  return out;
}

}  // namespace plslam::eval
