// Every analytic Jacobian against central finite differences (1e-6 relative, Frobenius norm) at
// >= 1000 random configurations, including points at the image border and lines nearly
// parallel to the image axes.
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "optim/synthetic_scene.h"
#include "plslam/optim/ceres_costs.h"
#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {
namespace {

using geometry::SE3;
using geometry::Vector6d;

constexpr double kRelTol = 1e-6;
constexpr int kConfigs = 1500;

// Central differences of f: R^n -> R^m around zero.
Eigen::MatrixXd numeric_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                 int n, double h) {
  Eigen::MatrixXd J;
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
    d(k) = h;
    const Eigen::VectorXd col = (f(d) - f(-d)) / (2.0 * h);
    if (k == 0) J.resize(col.size(), n);
    J.col(k) = col;
  }
  return J;
}

double rel_error(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric) {
  return (analytic - numeric).norm() / std::max(analytic.norm(), 1e-3);
}

// A pixel anywhere in the image; a third of them within one pixel of a border.
Eigen::Vector2d pixel_maybe_at_border(const geometry::StereoCamera& cam, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Vector2d p = test::random_pixel(cam, rng, 0.0);
  const double roll = u(rng);
  if (roll < 0.08) p.x() = u(rng);
  else if (roll < 0.16) p.x() = cam.width() - u(rng);
  else if (roll < 0.25) p.y() = u(rng);
  else if (roll < 0.33) p.y() = cam.height() - u(rng);
  return p;
}

TEST(Jacobians, StereoPointPoseAndPoint) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(1);
  double worst_pose = 0.0, worst_point = 0.0;
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 T = test::random_pose(rng, 5.0, 1.0);
    const Eigen::Vector3d X = test::world_point_at(cam, T, pixel_maybe_at_border(cam, rng),
                                                   test::random_depth(rng, 0.3, 80.0));
    const Eigen::Vector3d z = cam.project_stereo(T * X) + Eigen::Vector3d(3.0, -2.0, 1.5);
    const bool has_right = i % 5 != 0;
    Eigen::Vector3d r;
    Matrix36d Jp;
    Eigen::Matrix3d Jx;
    ASSERT_TRUE(evaluate_stereo_point(cam, T, X, z, has_right, &r, &Jp, &Jx));
    const auto f_pose = [&](const Eigen::VectorXd& d) {
      Eigen::Vector3d out;
      evaluate_stereo_point(cam, SE3::exp(Vector6d(d)) * T, X, z, has_right, &out, nullptr, nullptr);
      return Eigen::VectorXd(out);
    };
    const auto f_point = [&](const Eigen::VectorXd& d) {
      Eigen::Vector3d out;
      evaluate_stereo_point(cam, T, X + Eigen::Vector3d(d), z, has_right, &out, nullptr, nullptr);
      return Eigen::VectorXd(out);
    };
    const double ep = rel_error(Jp, numeric_jacobian(f_pose, 6, 1e-6));
    const double ex = rel_error(Jx, numeric_jacobian(f_point, 3, 1e-6));
    worst_pose = std::max(worst_pose, ep);
    worst_point = std::max(worst_point, ex);
    ASSERT_LT(ep, kRelTol) << "config " << i;
    ASSERT_LT(ex, kRelTol) << "config " << i;
    if (!has_right) {
      EXPECT_EQ(r(2), 0.0);
      EXPECT_EQ(Jp.row(2).norm(), 0.0);
    }
  }
  std::printf("stereo point: worst relative error pose %.2e point %.2e over %d configs\n",
              worst_pose, worst_point, kConfigs);
}

// Segment endpoints: a third near-horizontal, a third near-vertical, endpoints possibly at the
// image border.
std::pair<Eigen::Vector3d, Eigen::Vector3d> tricky_segment(const geometry::StereoCamera& cam,
                                                           const SE3& T, int i, std::mt19937& rng) {
  std::uniform_real_distribution<double> tiny(-1e-3, 1e-3), len(20.0, 400.0);
  const Eigen::Vector2d a = pixel_maybe_at_border(cam, rng);
  Eigen::Vector2d b = pixel_maybe_at_border(cam, rng);
  if (i % 3 == 0) b = {std::clamp(a.x() + len(rng), 0.0, cam.width() - 1.0) , a.y() + tiny(rng)};
  if (i % 3 == 1) b = {a.x() + tiny(rng), std::clamp(a.y() + len(rng) - 200.0, 0.0, cam.height() - 1.0)};
  if ((b - a).norm() < 5.0) b = a + Eigen::Vector2d(30.0, 20.0);
  return {test::world_point_at(cam, T, a, test::random_depth(rng, 0.5, 60.0)),
          test::world_point_at(cam, T, b, test::random_depth(rng, 0.5, 60.0))};
}

TEST(Jacobians, StereoLinePoseAndEndpoints) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(2);
  double worst = 0.0;
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 T = test::random_pose(rng, 5.0, 1.0);
    const auto [Ps, Pe] = tricky_segment(cam, T, i, rng);
    // Observed with 2 px noise so the residuals are not zero.
    const StereoLineObservation obs = test::observe_line(cam, T, Ps, Pe, 2.0, rng);
    Eigen::Vector4d r;
    Matrix46d Jp;
    Matrix43d Js, Je;
    ASSERT_TRUE(evaluate_stereo_line(cam, T, Ps, Pe, obs, &r, &Jp, &Js, &Je));
    const auto eval = [&](const SE3& TT, const Eigen::Vector3d& S, const Eigen::Vector3d& E) {
      Eigen::Vector4d out;
      evaluate_stereo_line(cam, TT, S, E, obs, &out, nullptr, nullptr, nullptr);
      return Eigen::VectorXd(out);
    };
    const double ep = rel_error(Jp, numeric_jacobian([&](const Eigen::VectorXd& d) {
      return eval(SE3::exp(Vector6d(d)) * T, Ps, Pe); }, 6, 1e-6));
    const double es = rel_error(Js, numeric_jacobian([&](const Eigen::VectorXd& d) {
      return eval(T, Ps + Eigen::Vector3d(d), Pe); }, 3, 1e-6));
    const double ee = rel_error(Je, numeric_jacobian([&](const Eigen::VectorXd& d) {
      return eval(T, Ps, Pe + Eigen::Vector3d(d)); }, 3, 1e-6));
    worst = std::max({worst, ep, es, ee});
    ASSERT_LT(ep, kRelTol) << "config " << i;
    ASSERT_LT(es, kRelTol) << "config " << i;
    ASSERT_LT(ee, kRelTol) << "config " << i;
  }
  std::printf("stereo line: worst relative error %.2e over %d configs\n", worst, kConfigs);
}

// The Ceres wrappers: J_ambient * PlusJacobian against differences through the manifold's Plus.
TEST(Jacobians, CeresCostsThroughTheSe3Manifold) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(3);
  const SE3LeftManifold manifold;
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jac;
  double worst = 0.0;
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 T = test::random_pose(rng, 5.0, 1.0);
    const PoseParams x = to_params(T);
    ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus_jac.data()));
    const auto plus = [&](const Eigen::VectorXd& d) {
      PoseParams y;
      manifold.Plus(x.data(), d.data(), y.data());
      return y;
    };

    // Point cost.
    const Eigen::Vector3d X = test::world_point_at(cam, T, pixel_maybe_at_border(cam, rng), test::random_depth(rng, 0.5, 60.0));
    StereoPointObservation po = test::observe_point(cam, T, X, 2.0, rng);
    po.level = i % 4;
    const StereoPointCost pc(cam, po, 0.7);
    Eigen::Matrix<double, 3, 7, Eigen::RowMajor> Jpa;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Jxa;
    Eigen::Vector3d rr;
    {
      const double* params[] = {x.data(), X.data()};
      double* jacs[] = {Jpa.data(), Jxa.data()};
      ASSERT_TRUE(pc.Evaluate(params, rr.data(), jacs));
    }
    const auto f_point_pose = [&](const Eigen::VectorXd& d) {
      const PoseParams y = plus(d);
      const double* params[] = {y.data(), X.data()};
      Eigen::Vector3d out;
      pc.Evaluate(params, out.data(), nullptr);
      return Eigen::VectorXd(out);
    };
    const auto f_point_x = [&](const Eigen::VectorXd& d) {
      const Eigen::Vector3d Y = X + Eigen::Vector3d(d);
      const double* params[] = {x.data(), Y.data()};
      Eigen::Vector3d out;
      pc.Evaluate(params, out.data(), nullptr);
      return Eigen::VectorXd(out);
    };
    const double e1 = rel_error(Jpa * plus_jac, numeric_jacobian(f_point_pose, 6, 1e-6));
    const double e2 = rel_error(Jxa, numeric_jacobian(f_point_x, 3, 1e-6));
    EXPECT_EQ(Jpa.col(6).norm(), 0.0);

    // Line pair cost, left and right image.
    const auto [Ps, Pe] = tricky_segment(cam, T, i, rng);
    const StereoLineObservation lo = test::observe_line(cam, T, Ps, Pe, 2.0, rng);
    double e3 = 0.0;
    for (const bool right : {false, true}) {
      const StereoLinePairCost lc(cam, lo, right, 0.5);
      Eigen::Matrix<double, 2, 7, Eigen::RowMajor> Jl;
      Eigen::Matrix<double, 2, 6, Eigen::RowMajor> Jse;
      Eigen::Vector2d rl;
      Eigen::Matrix<double, 6, 1> ends;
      ends << Ps, Pe;
      const double* params[] = {x.data(), ends.data()};
      double* jacs[] = {Jl.data(), Jse.data()};
      ASSERT_TRUE(lc.Evaluate(params, rl.data(), jacs));
      const auto f = [&](const Eigen::VectorXd& d, int block) {
        PoseParams y = x;
        Eigen::Matrix<double, 6, 1> e2 = ends;
        if (block == 0) y = plus(d);
        if (block == 1) e2 += d;
        const double* p2[] = {y.data(), e2.data()};
        Eigen::Vector2d out;
        lc.Evaluate(p2, out.data(), nullptr);
        return Eigen::VectorXd(out);
      };
      e3 = std::max({e3,
                     rel_error(Jl * plus_jac, numeric_jacobian([&](const Eigen::VectorXd& d) { return f(d, 0); }, 6, 1e-6)),
                     rel_error(Jse, numeric_jacobian([&](const Eigen::VectorXd& d) { return f(d, 1); }, 6, 1e-6))});
    }
    worst = std::max({worst, e1, e2, e3});
    ASSERT_LT(e1, kRelTol) << i;
    ASSERT_LT(e2, kRelTol) << i;
    ASSERT_LT(e3, kRelTol) << i;
  }
  std::printf("ceres point/line costs: worst relative error %.2e over %d configs\n", worst, kConfigs);
}

TEST(Jacobians, RelativePoseEdge) {
  std::mt19937 rng(4);
  const SE3LeftManifold manifold;
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jac;
  double worst = 0.0;
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 Ti = test::random_pose(rng, 5.0, 1.5);
    const SE3 Tj = test::random_pose(rng, 5.0, 1.5);
    // Measurement off by a small-to-large error so that e covers near-zero to ~2 rad.
    const double mag = (i % 3 == 0) ? 1e-7 : (i % 3 == 1 ? 0.05 : 0.7);
    const SE3 Z = test::random_pose(rng, mag, mag) * Ti * Tj.inverse();
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
    const geometry::Matrix6d info = A * A.transpose() + geometry::Matrix6d::Identity();
    const geometry::Matrix6d L = info.llt().matrixU();
    const RelativePoseCost cost(Z, L);
    const PoseParams xi = to_params(Ti), xj = to_params(Tj);
    Eigen::Matrix<double, 6, 7, Eigen::RowMajor> Ji, Jj;
    geometry::Vector6d r;
    const double* params[] = {xi.data(), xj.data()};
    double* jacs[] = {Ji.data(), Jj.data()};
    ASSERT_TRUE(cost.Evaluate(params, r.data(), jacs));
    manifold.PlusJacobian(xi.data(), plus_jac.data());
    const auto f = [&](const Eigen::VectorXd& d, bool first) {
      PoseParams a = xi, b = xj;
      if (first) manifold.Plus(xi.data(), d.data(), a.data());
      else manifold.Plus(xj.data(), d.data(), b.data());
      const double* p2[] = {a.data(), b.data()};
      geometry::Vector6d out;
      cost.Evaluate(p2, out.data(), nullptr);
      return Eigen::VectorXd(out);
    };
    const double ei = rel_error(Ji * plus_jac, numeric_jacobian([&](const Eigen::VectorXd& d) { return f(d, true); }, 6, 1e-6));
    const double ej = rel_error(Jj * plus_jac, numeric_jacobian([&](const Eigen::VectorXd& d) { return f(d, false); }, 6, 1e-6));
    worst = std::max({worst, ei, ej});
    ASSERT_LT(ei, kRelTol) << i;
    ASSERT_LT(ej, kRelTol) << i;
  }
  std::printf("relative pose edge: worst relative error %.2e over %d configs\n", worst, kConfigs);
}

// The pose-landmark block J_pose' w J_landmark as the structured form gives it: with BR = B R,
// the translation rows are BR and the rotation rows are Xc x (each column of BR).
Eigen::Matrix<double, 6, 3> pose_landmark_block(const Eigen::Matrix3d& BR, const Eigen::Vector3d& Xc) {
  Eigen::Matrix<double, 6, 3> W;
  W.topRows<3>() = BR;
  for (int j = 0; j < 3; ++j) W.block<3, 1>(3, j) = Xc.cross(BR.col(j));
  return W;
}

// The structured normal equations the optimisers accumulate (stereo_point_weighted_normal and
// add_pose_normal_equations) against the products of the explicit Jacobians.
TEST(Jacobians, StereoPointNormalEquationsFromStructure) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> weight(0.05, 3.0);
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 T = test::random_pose(rng, 5.0, 1.0);
    const Eigen::Vector3d X = test::world_point_at(cam, T, pixel_maybe_at_border(cam, rng),
                                                   test::random_depth(rng, 0.3, 80.0));
    const Eigen::Vector3d z = cam.project_stereo(T * X) + Eigen::Vector3d(3.0, -2.0, 1.5);
    const bool has_right = i % 5 != 0;
    const double w = weight(rng);
    Eigen::Vector3d r;
    Matrix36d Jp;
    Eigen::Matrix3d Jx;
    ASSERT_TRUE(evaluate_stereo_point(cam, T, X, z, has_right, &r, &Jp, &Jx));
    const Eigen::Vector3d Xc = T * X;
    EXPECT_EQ((stereo_point_residual_at(cam, Xc, z, has_right) - r).norm(), 0.0);
    Eigen::Matrix3d B;
    Eigen::Vector3d a;
    stereo_point_weighted_normal(cam, Xc, r, has_right, w, &B, &a);
    geometry::Matrix6d H = geometry::Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    add_pose_normal_equations(B, a, Xc, H, g);
    const geometry::Matrix6d H_ref = w * Jp.transpose() * Jp;
    const Vector6d g_ref = w * Jp.transpose() * r;
    const Eigen::Matrix3d Hx_ref = w * Jx.transpose() * Jx;
    const Eigen::Matrix<double, 6, 3> W_ref = w * Jp.transpose() * Jx;
    const Eigen::Matrix3d BR = B * T.rotation();
    const Eigen::Matrix<double, 6, 3> W = pose_landmark_block(BR, Xc);
    ASSERT_LT((H - H_ref).norm(), 1e-12 * H_ref.norm()) << i;
    ASSERT_LT((g - g_ref).norm(), 1e-12 * std::max(g_ref.norm(), 1e-300)) << i;
    ASSERT_LT((T.rotation().transpose() * BR - Hx_ref).norm(), 1e-12 * Hx_ref.norm()) << i;
    ASSERT_LT((T.rotation().transpose() * a - w * Jx.transpose() * r).norm(),
              1e-12 * std::max(g_ref.norm(), 1e-300)) << i;
    ASSERT_LT((W - W_ref).norm(), 1e-12 * W_ref.norm()) << i;
  }
}

// The same for a line observation: each endpoint as a weighted 2-row point observation.
TEST(Jacobians, StereoLineNormalEquationsFromStructure) {
  const auto cam = test::kitti_like_camera();
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> weight(0.05, 3.0);
  for (int i = 0; i < kConfigs; ++i) {
    const SE3 T = test::random_pose(rng, 5.0, 1.0);
    const auto [Ps, Pe] = test::random_segment(cam, T, rng);
    const StereoLineObservation o = test::observe_line(cam, T, Ps, Pe, 2.0, rng);
    const Eigen::Vector2d w(weight(rng), weight(rng));
    Eigen::Vector4d r;
    Matrix46d Jp;
    Matrix43d Js, Je;
    ASSERT_TRUE(evaluate_stereo_line(cam, T, Ps, Pe, o, &r, &Jp, &Js, &Je));
    const Eigen::Vector3d Xs = T * Ps, Xe = T * Pe;
    EXPECT_EQ((stereo_line_residual_at(cam, Xs, Xe, o) - r).norm(), 0.0);
    Eigen::Matrix3d B[2];
    Eigen::Vector3d a[2];
    stereo_line_weighted_normal(cam, Xs, Xe, o, r, w, B, a);
    geometry::Matrix6d H = geometry::Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    add_pose_normal_equations(B[0], a[0], Xs, H, g);
    add_pose_normal_equations(B[1], a[1], Xe, H, g);
    const Eigen::Vector4d wr(w(0), w(0), w(1), w(1));
    const geometry::Matrix6d H_ref = Jp.transpose() * wr.asDiagonal() * Jp;
    const Vector6d g_ref = Jp.transpose() * wr.asDiagonal() * r;
    ASSERT_LT((H - H_ref).norm(), 1e-12 * H_ref.norm()) << i;
    ASSERT_LT((g - g_ref).norm(), 1e-12 * std::max(g_ref.norm(), 1e-300)) << i;
    const Matrix43d* J[2] = {&Js, &Je};
    const Eigen::Vector3d* Xc[2] = {&Xs, &Xe};
    for (int x = 0; x < 2; ++x) {
      const Eigen::Matrix3d Hx_ref = J[x]->transpose() * wr.asDiagonal() * *J[x];
      const Eigen::Matrix<double, 6, 3> W_ref = Jp.transpose() * wr.asDiagonal() * *J[x];
      const Eigen::Matrix3d BR = B[x] * T.rotation();
      const Eigen::Matrix<double, 6, 3> W = pose_landmark_block(BR, *Xc[x]);
      ASSERT_LT((T.rotation().transpose() * BR - Hx_ref).norm(), 1e-12 * Hx_ref.norm()) << i;
      ASSERT_LT((T.rotation().transpose() * a[x] - J[x]->transpose() * wr.asDiagonal() * r).norm(),
                1e-12 * std::max(g_ref.norm(), 1e-300)) << i;
      ASSERT_LT((W - W_ref).norm(), 1e-12 * W_ref.norm()) << i;
    }
    // The endpoints do not couple: J_start' w J_end is zero.
    EXPECT_EQ((Js.transpose() * wr.asDiagonal() * Je).norm(), 0.0);
  }
}

TEST(Jacobians, BehindCameraIsReported) {
  const auto cam = test::kitti_like_camera();
  Eigen::Vector3d r;
  EXPECT_FALSE(evaluate_stereo_point(cam, SE3(), {0, 0, -1}, {0, 0, 0}, true, &r, nullptr, nullptr));
  Eigen::Vector4d rl;
  StereoLineObservation o;
  o.left_line = o.right_line = {1, 0, -100};
  EXPECT_FALSE(evaluate_stereo_line(cam, SE3(), {0, 0, 5}, {0, 0, -1}, o, &rl, nullptr, nullptr, nullptr));
}

}  // namespace
}  // namespace plslam::optim
