#pragma once
// Motion-only bundle adjustment over stereo points and stereo lines (ORB-SLAM2's
// PoseOptimization extended with lines): a hand-written Levenberg-Marquardt on the 6x6 normal
// equations (Ceres' per-problem overhead alone exceeds the 1 ms budget), run for `rounds`
// rounds of `iterations_per_round`; after each round every term is re-classified by its
// chi-square gate, so outliers can come back as inliers once the pose has improved.
#include <vector>

#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/observations.h"
#include "plslam/optim/robust.h"

namespace plslam::optim {

// A map point and its observation in the frame being optimised (keyframe/point indices unused).
struct PosePointTerm {
  Eigen::Vector3d world = Eigen::Vector3d::Zero();
  StereoPointObservation obs;
};

// A map line (world endpoints) and its stereo observation in the frame.
struct PoseLineTerm {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  StereoLineObservation obs;
};

struct PoseOnlyOptions {
  int rounds = 4;
  int iterations_per_round = 10;
  int robust_rounds = 3;  // the Huber kernel is used in the first rounds only (as ORB-SLAM2)
  double chi2_point_stereo = kChi2Stereo3Dof;
  double chi2_point_mono = kChi2Mono2Dof;
  double chi2_line_pair = kChi2LinePair2Dof;
  double scale_factor = 1.2;  // pyramid scale: sigma^2 = scale^(2 level)
  // Also return the pose's covariance (PoseOnlyResult::covariance): one more pass over the terms.
  bool covariance = false;
};

struct PoseOnlyResult {
  geometry::SE3 T_cw;
  std::vector<bool> point_outlier;  // one per input point term
  std::vector<bool> line_outlier;   // one per input line term
  int num_point_inliers = 0;
  int num_line_inliers = 0;
  // sum over the final inliers of chi2 (e' Omega e), after the last round (no kernel when the
  // last round is not robust).
  double final_cost = 0.0;
  int iterations = 0;  // LM iterations actually run
  // With PoseOnlyOptions::covariance: the inverse of the information matrix J' Omega J of the final
  // inliers at T_cw (no kernel), for the left perturbation T_cw_true = exp(delta) T_cw, delta =
  // (translation, rotation). That is also the covariance of xi in T_wc_true = T_wc exp(xi): the
  // camera's pose error in its own frame. Pixel noise is taken as 1 px at level 0 (the levels'
  // sigma^2 = scale^(2 level)), as in every other information matrix. Zero when the inliers leave
  // a direction unobserved.
  geometry::Matrix6d covariance = geometry::Matrix6d::Zero();
};

PoseOnlyResult optimize_pose(const geometry::StereoCamera& cam, const geometry::SE3& T_cw_init,
                             const std::vector<PosePointTerm>& points,
                             const std::vector<PoseLineTerm>& lines,
                             const PoseOnlyOptions& options = {});

}  // namespace plslam::optim
