#include "plslam/inertial/vi_initializer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <ceres/sphere_manifold.h>
#include <ceres/problem.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <fmt/format.h>

#include "plslam/inertial/preintegration.h"

namespace plslam::inertial {

void ViInitOptions::validate() const {
  if (min_keyframes < 2) throw std::invalid_argument("ViInitOptions: min_keyframes must be >= 2");
  if (!(min_span_s > 0)) throw std::invalid_argument("ViInitOptions: min_span_s must be > 0");
  if (!(max_gravity_sigma_deg > 0)) throw std::invalid_argument("ViInitOptions: max_gravity_sigma_deg must be > 0");
  if (!(max_rms_residual > 0)) throw std::invalid_argument("ViInitOptions: max_rms_residual must be > 0");
  if (!(gyro_bias_prior > 0) || !(acc_bias_prior > 0)) throw std::invalid_argument("ViInitOptions: bias priors must be > 0");
  if (max_relinearisations < 0) throw std::invalid_argument("ViInitOptions: max_relinearisations must be >= 0");
  if (!(pose_position_sigma >= 0) || !(pose_rotation_sigma >= 0) || !(pose_position_sigma_per_m >= 0)) {
    throw std::invalid_argument("ViInitOptions: pose sigmas must be >= 0");
  }
}

Eigen::Matrix3d ViInitResult::R_gw() const {
  return Eigen::Quaterniond::FromTwoVectors(gravity_direction, Eigen::Vector3d(0, 0, -1)).toRotationMatrix();
}

namespace {

// The IMU residual between keyframes i and j (as in imu_residual.h) with the rotations fixed and
// the gravity direction unknown: parameters gravity direction (3, unit), v_i, v_j, p_i, p_j (3) and
// the window's one bias [bg; ba] (6). The positions move under a prior (PositionPrior): each
// keyframe's error enters the two intervals it ends and starts, with opposite signs, which a
// per-interval weight could not say. Automatic differentiation: this runs once per attempt.
struct FixedRotationImuResidual {
  Eigen::Matrix3d R_i, R_j;
  double dt;
  Eigen::Matrix3d delta_R;
  Eigen::Vector3d delta_v, delta_p;
  Matrix96d J;  // rows [dphi; dv; dp], columns [dbg; dba]
  ImuBias linearisation;
  Matrix9d sqrt_info;

  template <class T>
  bool operator()(const T* g, const T* vi, const T* vj, const T* pi, const T* pj, const T* b, T* out) const {
    using V3 = Eigen::Matrix<T, 3, 1>;
    using M3 = Eigen::Matrix<T, 3, 3>;
    Eigen::Matrix<T, 6, 1> db;
    for (int k = 0; k < 3; ++k) {
      db(k) = b[k] - T(linearisation.gyro(k));
      db(3 + k) = b[3 + k] - T(linearisation.acc(k));
    }
    const Eigen::Matrix<T, 9, 1> d = J.cast<T>() * db;
    const V3 phi = d.template head<3>();
    M3 exp_phi;
    ceres::AngleAxisToRotationMatrix(phi.data(), exp_phi.data());
    const M3 E = (delta_R.cast<T>() * exp_phi).transpose() * (R_i.transpose() * R_j).cast<T>();
    V3 r_R;
    ceres::RotationMatrixToAngleAxis(E.data(), r_R.data());
    const V3 G = V3(g[0], g[1], g[2]) * T(kGravity);
    const V3 Vi(vi[0], vi[1], vi[2]), Vj(vj[0], vj[1], vj[2]), Pi(pi[0], pi[1], pi[2]), Pj(pj[0], pj[1], pj[2]);
    const M3 RiT = R_i.transpose().cast<T>();
    const V3 r_v = RiT * (Vj - Vi - G * T(dt)) - (delta_v.cast<T>() + d.template segment<3>(3));
    const V3 r_p = RiT * (Pj - Pi - Vi * T(dt) - G * T(0.5 * dt * dt)) -
                   (delta_p.cast<T>() + d.template segment<3>(6));
    Eigen::Matrix<T, 9, 1> r;
    r << r_R, r_v, r_p;
    Eigen::Map<Eigen::Matrix<T, 9, 1>> whitened(out);
    whitened = sqrt_info.cast<T>() * r;
    return true;
  }
};

struct PositionPrior {
  Eigen::Vector3d measured;
  double inv_sigma;
  template <class T>
  bool operator()(const T* p, T* out) const {
    for (int k = 0; k < 3; ++k) out[k] = (p[k] - T(measured(k))) * T(inv_sigma);
    return true;
  }
};

struct BiasPrior {
  double inv_sigma_gyro, inv_sigma_acc;
  template <class T>
  bool operator()(const T* b, T* out) const {
    for (int k = 0; k < 3; ++k) {
      out[k] = b[k] * T(inv_sigma_gyro);
      out[3 + k] = b[3 + k] * T(inv_sigma_acc);
    }
    return true;
  }
};

// The residual's covariance: the preintegration's, plus the two fixed rotations' errors.
Matrix9d sqrt_information(const Matrix9d& preintegration, const ViInitOptions& o) {
  Matrix9d covariance = preintegration;
  covariance.block<3, 3>(0, 0).diagonal().array() += 2 * o.pose_rotation_sigma * o.pose_rotation_sigma;
  const Eigen::LLT<Matrix9d> llt(covariance.inverse());
  if (llt.info() != Eigen::Success) throw std::invalid_argument("IMU covariance not positive definite");
  return llt.matrixU();  // U' U = information
}

double rotation_angle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

}  // namespace

ViInitResult initialize_visual_inertial(std::span<const ViKeyframe> keyframes, const ImuData& imu,
                                        const ViInitOptions& options) {
  options.validate();
  const auto start = std::chrono::steady_clock::now();
  ViInitResult res;
  res.keyframes = static_cast<int>(keyframes.size());
  if (keyframes.empty()) {
    res.reason = "no keyframes";
    return res;
  }
  res.span_s = keyframes.back().t - keyframes.front().t;
  for (const ViKeyframe& k : keyframes) {
    res.rotation_deg = std::max(res.rotation_deg,
                                rotation_angle(keyframes.front().T_wc.linear().transpose() * k.T_wc.linear()) * 180 / M_PI);
  }
  if (res.keyframes < options.min_keyframes) {
    res.reason = fmt::format("{} keyframes, {} needed", res.keyframes, options.min_keyframes);
    return res;
  }
  if (res.span_s < options.min_span_s) {
    res.reason = fmt::format("keyframes span {:.2f} s, {:.2f} s needed", res.span_s, options.min_span_s);
    return res;
  }
  const auto& S = imu.samples;
  if (S.empty() || S.front().t > keyframes.front().t || S.back().t < keyframes.back().t) {
    res.reason = "the IMU does not cover the keyframes";
    return res;
  }
  // Body (IMU) poses in the visual world: T_wb = T_wc * T_cb.
  const Eigen::Isometry3d T_cb = imu.T_imu_cam.inverse();
  const std::size_t n = keyframes.size();
  std::vector<Eigen::Matrix3d> R(n);
  std::vector<Eigen::Vector3d> p(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Isometry3d T_wb = keyframes[k].T_wc * T_cb;
    R[k] = T_wb.linear();
    p[k] = T_wb.translation();
  }
  const std::vector<Eigen::Vector3d> p_measured = p;  // the priors' centres; p moves
  // The position priors' widths: they grow with the path travelled since the window's first keyframe.
  std::vector<double> position_sigma(n);
  double path = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) path += (p_measured[k] - p_measured[k - 1]).norm();
    position_sigma[k] = std::hypot(options.pose_position_sigma, options.pose_position_sigma_per_m * path);
  }
  std::vector<Preintegration> pre;
  ImuBias bias;
  try {
    for (std::size_t k = 0; k + 1 < n; ++k) {
      pre.emplace_back(std::span<const ImuSample>(S), keyframes[k].t, keyframes[k + 1].t, bias, imu.calibration.noise);
    }
  } catch (const std::invalid_argument& e) {
    res.reason = std::string("cannot preintegrate the IMU: ") + e.what();
    return res;
  }
  // Starting values: velocities from the positions, gravity from the mean specific force in the
  // world (sum of R_i delta_v = velocity change - gravity * time).
  std::vector<Eigen::Vector3d> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? n - 1 : k + 1;
    v[k] = (p[b] - p[a]) / (keyframes[b].t - keyframes[a].t);
  }
  Eigen::Vector3d specific = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k + 1 < n; ++k) specific += R[k] * pre[k].delta_v();
  const Eigen::Vector3d g0 = (v[n - 1] - v[0]) - specific;
  if (!(g0.norm() > 0)) {
    res.reason = "no specific force";
    return res;
  }
  Eigen::Vector3d g = g0.normalized();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();

  ceres::Solver::Summary summary;
  std::unique_ptr<ceres::Problem> problem;
  for (int pass = 0; pass <= options.max_relinearisations; ++pass) {
    problem = std::make_unique<ceres::Problem>();
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const Preintegration& q = pre[k];
      auto* f = new FixedRotationImuResidual{R[k], R[k + 1], q.dt(), q.delta_R(), q.delta_v(), q.delta_p(),
                                             q.bias_jacobian(), q.linearisation_bias(), sqrt_information(q.covariance(), options)};
      problem->AddResidualBlock(new ceres::AutoDiffCostFunction<FixedRotationImuResidual, 9, 3, 3, 3, 3, 3, 6>(f), nullptr,
                                g.data(), v[k].data(), v[k + 1].data(), p[k].data(), p[k + 1].data(), b.data());
    }
    for (std::size_t k = 0; k < n; ++k) {
      if (options.pose_position_sigma > 0) {
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<PositionPrior, 3, 3>(
                                      new PositionPrior{p_measured[k], 1 / position_sigma[k]}),
                                  nullptr, p[k].data());
      } else {
        problem->SetParameterBlockConstant(p[k].data());
      }
    }
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPrior, 6, 6>(
                                  new BiasPrior{1 / options.gyro_bias_prior, 1 / options.acc_bias_prior}),
                              nullptr, b.data());
    problem->SetManifold(g.data(), new ceres::SphereManifold<3>());
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;  // banded in time: DENSE_QR took ~100 ms on 5 s
    so.max_num_iterations = 50;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    ceres::Solve(so, problem.get(), &summary);
    const ImuBias nb = ImuBias::from_vector(b.data());
    bool far = false;
    for (const Preintegration& q : pre) far = far || q.bias_moved_far(nb);
    if (!far || pass == options.max_relinearisations) break;
    for (Preintegration& q : pre) q.reintegrate(nb);
  }
  res.solved = true;
  res.gravity_direction = g.normalized();
  res.bias = ImuBias::from_vector(b.data());
  res.velocities = v;
  const double imu_residuals = 9.0 * static_cast<double>(n - 1);
  // The final cost includes the priors' share.
  res.rms_residual = std::sqrt(2 * summary.final_cost / imu_residuals);

  // Marginal covariances of the gravity direction (its 2-dof tangent) and the bias, from the normal
  // equations (sparse: banded in time), solved for those 8 columns only.
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = {g.data(), b.data()};
  for (std::size_t k = 0; k < n; ++k) eo.parameter_blocks.push_back(v[k].data());
  for (std::size_t k = 0; k < n; ++k) eo.parameter_blocks.push_back(p[k].data());
  eo.num_threads = 1;
  ceres::CRSMatrix crs;
  problem->Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[static_cast<std::size_t>(r)]; i < crs.rows[static_cast<std::size_t>(r) + 1]; ++i) {
      entries.emplace_back(r, crs.cols[static_cast<std::size_t>(i)], crs.values[static_cast<std::size_t>(i)]);
    }
  }
  Eigen::SparseMatrix<double> J(crs.num_rows, crs.num_cols);
  J.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> H = J.transpose() * J;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  const bool definite = ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff();
  if (!definite) {
    res.reason = "the estimate's covariance could not be computed (rank-deficient)";
  } else {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(H.rows(), 8);
    E.topRows<8>().setIdentity();
    const Eigen::MatrixXd C = ldlt.solve(E).topRows<8>();  // [gravity tangent (2); bias (6)]
    const Eigen::Matrix2d Cg = 0.5 * (C.block<2, 2>(0, 0) + C.block<2, 2>(0, 0).transpose());
    res.gravity_sigma_deg = std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(Cg).eigenvalues()(1))) * 180 / M_PI;
    for (int k = 0; k < 3; ++k) {
      res.gyro_bias_sigma(k) = std::sqrt(std::max(0.0, C(2 + k, 2 + k)));
      res.acc_bias_sigma(k) = std::sqrt(std::max(0.0, C(5 + k, 5 + k)));
    }
    if (summary.termination_type != ceres::CONVERGENCE) {
      res.reason = "the solver did not converge";
    } else if (res.rms_residual > options.max_rms_residual) {
      res.reason = fmt::format("the IMU and the keyframe poses disagree (whitened RMS {:.2f} > {:.2f})", res.rms_residual,
                               options.max_rms_residual);
    } else if (res.gravity_sigma_deg > options.max_gravity_sigma_deg) {
      res.reason = fmt::format("gravity not observable yet (sigma {:.2f} deg > {:.2f} deg; rotation so far {:.1f} deg)",
                               res.gravity_sigma_deg, options.max_gravity_sigma_deg, res.rotation_deg);
    } else {
      res.accepted = true;
    }
  }
  res.solve_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return res;
}

}  // namespace plslam::inertial
