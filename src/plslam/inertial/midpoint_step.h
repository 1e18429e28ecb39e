#pragma once
// One step of IMU preintegration with the midpoint rule, the only integration scheme of
// inertial/. Between two samples the step uses the mean of their (bias-corrected) gyro readings,
// w, and of their accelerometer readings, a, over the step's length dt:
//   R' = R Exp(w dt)
//   v' = v + M a dt,   p' = p + v dt + M a dt^2 / 2,   with M = R Exp(w dt / 2),
// M being the rotation at mid-step. Both halves matter for the order: the averaged rate makes the
// rotation second order, and rotating the mean specific force by the mid-step rotation (rather
// than by R, the rotation at the step's start, which would leave an O(dt) global error in v and
// p) makes velocity and position second order too: halving dt divides the error by four.
#include <Eigen/Core>

namespace plslam::inertial {

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Matrix96d = Eigen::Matrix<double, 9, 6>;
using Vector9d = Eigen::Matrix<double, 9, 1>;

// The motion from the interval's start, in the body frame at that start, with gravity left out:
// the body's rotation, and its velocity and position change minus what gravity contributed.
struct PreintegratedDeltas {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

// The step linearised in the error state e = [dphi; dv; dp] (R_true = R Exp(dphi),
// v_true = v + dv, p_true = p + dp) and in errors n = [n_g; n_a] added to the step's mean gyro
// and acc: e' = A e + B n. A bias error enters as n = -[dbg; dba]. By 3x3 blocks,
// A = [X 0 0; X I 0; X dt*I I] and B = [X 0; X X; X X].
struct StepTransition {
  Matrix9d A;
  Matrix96d B;

  // A M, skipping the products with A's zero and identity blocks (a third of the dense cost).
  template <int Cols>
  Eigen::Matrix<double, 9, Cols> A_times(const Eigen::Matrix<double, 9, Cols>& M) const {
    Eigen::Matrix<double, 9, Cols> out;
    const auto M_phi = M.template topRows<3>();
    out.template topRows<3>().noalias() = A.block<3, 3>(0, 0) * M_phi;
    out.template middleRows<3>(3) = M.template middleRows<3>(3);
    out.template middleRows<3>(3).noalias() += A.block<3, 3>(3, 0) * M_phi;
    out.template bottomRows<3>() =
        M.template bottomRows<3>() + A(6, 3) * M.template middleRows<3>(3);
    out.template bottomRows<3>().noalias() += A.block<3, 3>(6, 0) * M_phi;
    return out;
  }
};

// `gyro` and `acc` are the step's bias-corrected means; dt > 0. With `transition`, also A and B.
PreintegratedDeltas midpoint_step(const PreintegratedDeltas& d, const Eigen::Vector3d& gyro,
                                  const Eigen::Vector3d& acc, double dt,
                                  StepTransition* transition = nullptr);

}  // namespace plslam::inertial
