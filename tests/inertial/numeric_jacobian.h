#pragma once
// Central finite differences for the inertial tests.
#include <algorithm>
#include <functional>

#include <Eigen/Core>

namespace plslam::inertial::test {

// d f / d delta at delta = 0, column by column, f: R^n -> R^m.
inline Eigen::MatrixXd central_differences(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, int n, double h) {
  Eigen::MatrixXd J;
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
    d(k) = h;
    const Eigen::VectorXd column = (f(d) - f(-d)) / (2.0 * h);
    if (k == 0) J.resize(column.size(), n);
    J.col(k) = column;
  }
  return J;
}

// ||analytic - numeric|| / ||analytic|| (Frobenius), with a floor against all-zero blocks.
inline double relative_error(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric) {
  return (analytic - numeric).norm() / std::max(analytic.norm(), 1e-9);
}

}  // namespace plslam::inertial::test
