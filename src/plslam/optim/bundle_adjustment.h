#pragma once
// Stereo point + line bundle adjustment with the analytic residuals of stereo_point_residual.h /
// stereo_line_residual.h and the landmarks eliminated by the Schur complement. Two backends
// minimise the same cost: a hand-written Levenberg-Marquardt with a dense reduced camera system
// (ba_schur_lm.cpp, the default: several times faster for local windows) and Ceres
// (ba_ceres_pass.cpp, DENSE_SCHUR / SPARSE_SCHUR). The problem is plain data: keyframe
// poses T_cw with fixed flags, landmarks, and observations indexing them. A local BA is this
// problem restricted to a window, with the covisible keyframes outside it marked fixed.
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/geometry/triangulation.h"
#include "plslam/optim/ba_keyframe_factor.h"
#include "plslam/optim/observations.h"
#include "plslam/optim/robust.h"

namespace plslam::optim {

struct BaKeyframe {
  geometry::SE3 T_cw;
  bool fixed = false;
};

struct BaPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  bool fixed = false;
};

// A 3D line parameterised by its two world endpoints (each 3 DoF). The position of an endpoint
// along the line is not observable; the LM damping keeps it where it is.
struct BaLine {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  bool fixed = false;
};

struct BaProblem {
  std::vector<BaKeyframe> keyframes;
  std::vector<BaPoint> points;
  std::vector<BaLine> lines;
  std::vector<StereoPointObservation> point_observations;
  std::vector<StereoLineObservation> line_observations;
  // Factors between keyframes (ba_keyframe_factor.h: the IMU's, in a visual-inertial BA) and, with
  // them, one extra state per keyframe, which moves with its keyframe's pose and is held with it.
  // Both backends take them; kSchurLM hands a problem to Ceres' SPARSE_SCHUR once its dense system
  // (15 per free keyframe with factors) passes 6 max_dense_keyframes.
  std::vector<Vector9d> keyframe_extra;
  std::vector<std::shared_ptr<const BaKeyframeFactor>> keyframe_factors;
};

enum class BaLinearSolver { kDenseSchur, kSparseSchur };  // Ceres backend only

enum class BaBackend {
  kSchurLM,  // hand-written LM, dense reduced camera system (6 unknowns per free keyframe)
  kCeres,    // Ceres 2.1 with `linear_solver`
};

struct BaOptions {
  int iterations = 10;  // LM iterations of the first pass
  // Stop a pass when a step changes the cost by less than this fraction (Ceres' default);
  // 0 runs every iteration (benchmarks at a fixed iteration count).
  double function_tolerance = 1e-6;
  // After the first (robust) pass, drop the observations beyond their chi-square gate and run
  // `second_pass_iterations` more without the robust kernel (ORB-SLAM2's local BA).
  bool remove_outliers = false;
  int second_pass_iterations = 10;
  bool robust = true;
  double chi2_point_stereo = kChi2Stereo3Dof;
  double chi2_point_mono = kChi2Mono2Dof;
  double chi2_line_pair = kChi2LinePair2Dof;
  double scale_factor = 1.2;
  BaBackend backend = BaBackend::kSchurLM;
  // kSchurLM factors a dense (6 n)^2 camera system; with more free keyframes than this the
  // problem goes to Ceres' SPARSE_SCHUR instead (a large global BA).
  int max_dense_keyframes = 300;
  BaLinearSolver linear_solver = BaLinearSolver::kDenseSchur;
  int num_threads = 1;  // both backends (kSchurLM: core::WorkerPool over landmarks, fixed ranges)
  // Set from another thread to stop after the current iteration (a global BA that a new loop
  // makes obsolete); the result then says `aborted`. Not owned; may be null.
  const std::atomic<bool>* abort = nullptr;
};

struct BaResult {
  std::vector<geometry::SE3> poses;            // one per keyframe (fixed ones unchanged)
  std::vector<Eigen::Vector3d> points;         // one per point
  std::vector<geometry::Segment3d> lines;      // one per line
  std::vector<Vector9d> keyframe_extra;        // as the problem's (fixed ones unchanged)
  std::vector<bool> point_observation_outlier;  // per observation, gated at the final state
  std::vector<bool> line_observation_outlier;
  double initial_cost = 0.0;  // cost (1/2 sum rho, Ceres' definition) at the start of pass 1
  double final_cost = 0.0;    // ... at the end of the last pass
  int iterations = 0;
  bool usable = false;  // the solver produced a usable solution (false: no observations)
  bool aborted = false;  // options.abort was raised: the state is partial
  std::string message;  // the solver's brief report of the last pass (for logs)
};

// Throws InputError when an observation or a keyframe factor indexes outside the problem's arrays,
// or when there are factors and not one extra state per keyframe.
// An observation whose landmark is behind its camera at the start of a pass makes the Ceres
// backend fail (usable = false); kSchurLM leaves it out of that pass instead. Either way it is
// flagged as an outlier in the result.
BaResult bundle_adjust(const geometry::StereoCamera& cam, const BaProblem& problem,
                       const BaOptions& options = {});

// Local BA: bundle_adjust with remove_outliers on. When no keyframe is marked fixed the first one
// is fixed to remove the gauge freedom.
BaResult local_bundle_adjustment(const geometry::StereoCamera& cam, const BaProblem& problem,
                                 BaOptions options = {});

// Global BA: all keyframes free except the first.
BaResult global_bundle_adjustment(const geometry::StereoCamera& cam, const BaProblem& problem,
                                  const BaOptions& options = {});

}  // namespace plslam::optim
