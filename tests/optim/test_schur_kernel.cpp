// The Schur elimination kernel of the hand-written BA (schur_kernel.h): both implementations
// against a plain Eigen rendering of its contract, on random observation patterns (fixed cameras,
// a camera observing the landmark twice, points and lines).
#include <random>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "plslam/optim/schur_kernel.h"

namespace plslam::optim {
namespace {

Eigen::MatrixXd reference(int k, const std::vector<int>& cam, const Eigen::MatrixXd& Y,
                          const Eigen::MatrixXd& W, Eigen::MatrixXd S) {
  const int m = static_cast<int>(cam.size());
  const auto blk = [&](int a) { return Eigen::MatrixXd(Y.middleCols(k * a, k)); };
  const auto wblk = [&](int a) { return Eigen::MatrixXd(W.middleCols(k * a, k)); };
  for (int a = 0; a < m; ++a) {
    for (int c = a; c < m; ++c) {
      const int ca = cam[static_cast<std::size_t>(a)], cc = cam[static_cast<std::size_t>(c)];
      if (ca < 0 || cc < 0) continue;
      if (ca <= cc) S.block(6 * ca, 6 * cc, 6, 6) -= blk(a) * wblk(c).transpose();
      if (ca > cc) S.block(6 * cc, 6 * ca, 6, 6) -= blk(c) * wblk(a).transpose();
      if (ca == cc && a != c) S.block(6 * ca, 6 * ca, 6, 6) -= blk(c) * wblk(a).transpose();
    }
  }
  return S;
}

TEST(SchurKernel, BothImplementationsMatchTheReference) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> slot(-1, 4), count(1, 12);
  const int n_cams = 5;
  std::printf("best Schur kernel on this CPU: %s\n", to_string(best_schur_kernel()));
  for (int trial = 0; trial < 400; ++trial) {
    const int k = trial % 2 == 0 ? 3 : 6;
    const int m = count(rng);
    std::vector<int> cam(static_cast<std::size_t>(m));
    for (int& c : cam) c = slot(rng);
    Eigen::MatrixXd Y(6, k * m), W(6, k * m), S(6 * n_cams, 6 * n_cams);
    for (Eigen::Index i = 0; i < Y.size(); ++i) Y(i) = u(rng);
    for (Eigen::Index i = 0; i < W.size(); ++i) W(i) = u(rng);
    for (Eigen::Index i = 0; i < S.size(); ++i) S(i) = u(rng);
    const Eigen::MatrixXd expected = reference(k, cam, Y, W, S);
    for (const auto impl : {SchurKernelImpl::kPortable, SchurKernelImpl::kAvx2Fma}) {
      Eigen::MatrixXd out = S;
      schur_landmark_update(impl, k, m, cam.data(), Y.data(), W.data(), out.data(), out.rows());
      // Untouched entries stay bit-exact; updated ones agree to rounding (FMA rounds once).
      for (Eigen::Index j = 0; j < S.cols(); ++j) {
        for (Eigen::Index i = 0; i < S.rows(); ++i) {
          if (expected(i, j) == S(i, j)) {
            ASSERT_EQ(out(i, j), S(i, j)) << to_string(impl) << " trial " << trial;
          } else {
            ASSERT_NEAR(out(i, j), expected(i, j), 1e-13 * (1.0 + 2.0 * m * k))
                << to_string(impl) << " trial " << trial << " (" << i << ", " << j << ")";
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace plslam::optim
