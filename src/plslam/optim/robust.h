#pragma once
// Chi-square gates and the Huber kernel shared by every optimiser.
//
// Points: the stereo residual (u_l, v, u_r) has 3 DoF -> chi2(3, 95 %) = 7.815; an observation
// without a right match has 2 DoF -> chi2(2, 95 %) = 5.991.
// Lines: the 4 residuals of a stereo line observation are gated as two PAIRS, the left-image pair
// (distances of P_s, P_e to the left line) and the right-image pair. Within a pair both distances
// measure the same detected segment (2 DoF, chi2(2, 95 %) = 5.991); the two pairs come from
// independent detections, and a wrong right match -- the typical stereo line failure, since lines
// close to horizontal are ambiguous along the epipolar line -- corrupts only the right pair. A
// per-pair Huber kernel therefore down-weights a bad right match without discarding the left
// constraint, and a line observation is classified as an outlier when either pair exceeds the gate.
#include <cmath>

namespace plslam::optim {

inline constexpr double kChi2Stereo3Dof = 7.815;
inline constexpr double kChi2Mono2Dof = 5.991;
inline constexpr double kChi2LinePair2Dof = 5.991;

// Huber kernel on a squared, whitened error s = e' Omega e with threshold delta^2 = th (in chi2
// units, as in g2o): rho(s) = s for s <= th, 2 sqrt(th s) - th beyond.
struct Huber {
  double th;
  double rho(double s) const { return s <= th ? s : 2.0 * std::sqrt(th * s) - th; }
  // rho'(s): the IRLS weight.
  double weight(double s) const { return s <= th ? 1.0 : std::sqrt(th / s); }
};

// Inverse variance of a keypoint detected at pyramid `level`: sigma^2 = scale^(2 level).
inline double level_information(int level, double scale_factor = 1.2) {
  return 1.0 / std::pow(scale_factor, 2.0 * level);
}

}  // namespace plslam::optim
