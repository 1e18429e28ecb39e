#pragma once
// Internal interface between bundle_adjust (outlier passes, gating, results) and its two solver
// backends: one pass = one robust or plain LM run over the observations not excluded, updating
// the state in place. Both backends minimise the same cost, 1/2 sum rho(s) over point blocks
// (3 rows) and line image pairs (2 rows), s the whitened squared error.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/bundle_adjustment.h"

namespace plslam::optim {

struct BaState {
  std::vector<geometry::SE3> poses;                 // T_cw per keyframe
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix<double, 6, 1>> lines;  // [start; end]
  std::vector<Vector9d> extra;                      // per keyframe, with keyframe factors
};

// Observations left out of a pass (indexed like the problem's observation arrays).
struct BaExclusions {
  std::vector<bool> point_out, line_out;
};

struct BaPassSummary {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  bool usable = false;
  std::string message;
};

struct BaPassSpec {
  bool robust = true;
  int iterations = 10;
  const BaExclusions* excluded = nullptr;  // null: every observation takes part
};

// spec's exclusions plus the observations whose landmark is behind its camera at s: Ceres refuses
// to start from them, the Schur backend leaves them out of the pass; the final gate flags them.
BaExclusions with_behind_camera(const BaProblem& p, const BaPassSpec& spec, const BaState& s);

BaPassSummary ceres_ba_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                            const BaOptions& opt, const BaPassSpec& spec, BaState* s);

BaPassSummary schur_lm_ba_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                               const BaOptions& opt, const BaPassSpec& spec, BaState* s);

}  // namespace plslam::optim
