// The hand-written backend of bundle_adjust: Levenberg-Marquardt on the IRLS normal equations
// with every landmark eliminated by the Schur complement. Why not Ceres: a local BA has ~40k tiny
// residual blocks and Ceres' per-block bookkeeping costs several times the arithmetic; here each
// observation is a handful of fixed-size Eigen products on contiguous arrays.
//
// Normal equations with IRLS weights w = info * rho'(s) per robust block (this is exactly what
// Ceres does with a Huber loss: rho'' <= 0, so its corrector only rescales by sqrt(rho')):
//     [ C   W ] [dc]   [-g_c]        C: 6x6 block per free keyframe
//     [ W'  L ] [dl] = [-g_l]        L: 3x3 block per free point, 6x6 per free line
// Reduced camera system  (C - W L^-1 W') dc = -(g_c - W L^-1 g_l), dense (6 n_cams)^2, Cholesky;
// back-substitution      dl = -L^-1 (g_l + W' dc).
// Damping as Ceres' LM: lambda * clamp(diag(H), 1e-6, 1e32) on every block. It also keeps the
// 6x6 line blocks invertible although their endpoints can slide along the 3D line (each block has
// a 2-D null space; the gradient has no component there, so the damped step stays put).
// Pose update on the left, T <- exp(dc) T, as the residual Jacobians assume.
// Keyframe factors (ba_keyframe_factor.h: the IMU's) tie keyframes with no landmark between them:
// their normal equations go straight into the reduced system, which then also holds the free
// keyframes' extra states (9 each) after the 6 n_cams pose unknowns.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Cholesky>

#include "plslam/core/worker_pool.h"
#include "plslam/optim/ba_pass.h"
#include "plslam/optim/robust.h"
#include "plslam/optim/schur_kernel.h"
#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {
namespace {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

// Ceres' LM defaults, so both backends stop in the same situations.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kInitialLambda = 1e-4;
constexpr double kMinLambda = 1e-12;  // floor: the line gauge stays damped (Ceres: 1e-16)
constexpr double kMaxLambda = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

double damping_diagonal(double h) { return std::clamp(h, kMinDiagonal, kMaxDiagonal); }

// Inverse of a symmetric positive definite block; false when it is not positive definite.
// 3x3 (points, most of the work): cofactors, with Sylvester's criterion as the definiteness test,
// several times cheaper than a Cholesky solve against the identity.
bool invert_spd(const Eigen::Matrix3d& A, Eigen::Matrix3d* inv) {
  const double c00 = A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1);
  const double c01 = A(1, 2) * A(2, 0) - A(1, 0) * A(2, 2);
  const double c02 = A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0);
  const double det = A(0, 0) * c00 + A(0, 1) * c01 + A(0, 2) * c02;
  const double minor2 = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  if (!(A(0, 0) > 0.0) || !(minor2 > 0.0) || !(det > 0.0)) return false;
  const double id = 1.0 / det;
  (*inv)(0, 0) = c00 * id;
  (*inv)(1, 0) = (*inv)(0, 1) = c01 * id;
  (*inv)(2, 0) = (*inv)(0, 2) = c02 * id;
  (*inv)(1, 1) = (A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0)) * id;
  (*inv)(2, 1) = (*inv)(1, 2) = (A(0, 2) * A(1, 0) - A(0, 0) * A(1, 2)) * id;
  (*inv)(2, 2) = minor2 * id;
  return true;
}

bool invert_spd(const Matrix6d& A, Matrix6d* inv) {
  const Eigen::LLT<Matrix6d> llt(A);
  if (llt.info() != Eigen::Success) return false;
  *inv = llt.solve(Matrix6d::Identity());
  return true;
}

struct Context {
  const geometry::StereoCamera& cam;
  const BaOptions& opt;
  bool robust;
};

// A point observation linearised through its projection Jacobian A = d(projection)/d(X_c):
// J_pose = A [I, -hat(X_c)] and J_point = A R, so with B = w A'A and a = w A'r every block of the
// normal equations is a 3x3 product or a few cross products (add_pose_normal_equations):
//   J_point' w J_point = R' B R,   J_point' w r = R' a,   W = J_pose' w J_point = [BR; X_c x BR].
// The weight w (information times the Huber weight) is one scalar for the three rows.
struct PointLinearization {
  Eigen::Matrix3d B, BR;
  Eigen::Vector3d a, Xc;
  double rho;
};

// False when the point is behind the camera. Written on locals (no output pointers that could
// alias X_c), so 1/z is computed once. Forcing it inline was measured slower (code size).
bool linearize_point(const Context& c, const StereoPointObservation& o,
                                                   double info, const SE3& T,
                                                   const Eigen::Vector3d& X, PointLinearization& lin) {
  const Eigen::Vector3d Xc = T * X;
  if (!(Xc.z() > 0.0)) return false;
  const Eigen::Vector3d r = stereo_point_residual_at(c.cam, Xc, o.measurement, o.has_right);
  const double s = info * r.squaredNorm();
  const Huber h{o.has_right ? c.opt.chi2_point_stereo : c.opt.chi2_point_mono};
  lin.rho = c.robust ? h.rho(s) : s;
  const double w = info * (c.robust ? h.weight(s) : 1.0);
  Eigen::Matrix3d B;
  Eigen::Vector3d a;
  stereo_point_weighted_normal(c.cam, Xc, r, o.has_right, w, &B, &a);
  // B R with B(0,1) = B(1,0) = 0.
  const Eigen::Matrix3d& Rm = T.rotation();
  lin.BR.row(0) = B(0, 0) * Rm.row(0) + B(0, 2) * Rm.row(2);
  lin.BR.row(1) = B(1, 1) * Rm.row(1) + B(1, 2) * Rm.row(2);
  lin.BR.row(2) = B(2, 0) * Rm.row(0) + B(2, 1) * Rm.row(1) + B(2, 2) * Rm.row(2);
  lin.B = B;
  lin.a = a;
  lin.Xc = Xc;
  return true;
}

// A line observation: each endpoint x is a point observation of its own (rows 0, 2 the start,
// rows 1, 3 the end; stereo_line_weighted_normal), so the line's landmark block is
// blockdiag(R' B_s R, R' B_e R) and W = [W_s, W_e] with W_x = [B_x R; X_x x B_x R].
struct LineLinearization {
  Eigen::Matrix3d B[2], BR[2];
  Eigen::Vector3d a[2], Xc[2];
  double rho;
};

bool linearize_line(const Context& c, const StereoLineObservation& o,
                                                  double info, const SE3& T, const Vector6d& L,
                                                  LineLinearization& lin) {
  const Eigen::Vector3d Xs = T * Eigen::Vector3d(L.head<3>());
  const Eigen::Vector3d Xe = T * Eigen::Vector3d(L.tail<3>());
  if (!(Xs.z() > 0.0) || !(Xe.z() > 0.0)) return false;
  const Eigen::Vector4d r = stereo_line_residual_at(c.cam, Xs, Xe, o);
  const Huber h{c.opt.chi2_line_pair};
  Eigen::Vector2d w;
  lin.rho = 0.0;
  for (int pair = 0; pair < 2; ++pair) {  // left image rows 0-1, right image rows 2-3
    const double s = info * r.segment<2>(2 * pair).squaredNorm();
    lin.rho += c.robust ? h.rho(s) : s;
    w(pair) = info * (c.robust ? h.weight(s) : 1.0);
  }
  stereo_line_weighted_normal(c.cam, Xs, Xe, o, r, w, lin.B, lin.a);
  for (int x = 0; x < 2; ++x) lin.BR[x].noalias() = lin.B[x].lazyProduct(T.rotation());
  lin.Xc[0] = Xs;
  lin.Xc[1] = Xe;
  return true;
}

// Where the two landmark kinds differ: their arrays in the problem and in the state.
struct PointKind {
  static constexpr int N = 3;  // parameters per landmark
  using Obs = StereoPointObservation;
  using Vec = Eigen::Vector3d;
  static const std::vector<Obs>& observations(const BaProblem& p) { return p.point_observations; }
  static int landmark(const Obs& o) { return o.point; }
  static bool fixed(const BaProblem& p, int i) { return p.points[static_cast<std::size_t>(i)].fixed; }
  static std::size_t count(const BaProblem& p) { return p.points.size(); }
  static std::vector<Vec>& values(BaState& s) { return s.points; }
  static double info(const Obs& o, const BaOptions& opt) {
    return level_information(o.level, opt.scale_factor);
  }
  static const std::vector<bool>* excluded(const BaExclusions* e) { return e ? &e->point_out : nullptr; }
};

struct LineKind {
  static constexpr int N = 6;
  using Obs = StereoLineObservation;
  using Vec = Vector6d;
  static const std::vector<Obs>& observations(const BaProblem& p) { return p.line_observations; }
  static int landmark(const Obs& o) { return o.line; }
  static bool fixed(const BaProblem& p, int i) { return p.lines[static_cast<std::size_t>(i)].fixed; }
  static std::size_t count(const BaProblem& p) { return p.lines.size(); }
  static std::vector<Vec>& values(BaState& s) { return s.lines; }
  static double info(const Obs& o, const BaOptions& opt) {
    return o.information * level_information(o.level, opt.scale_factor);
  }
  static const std::vector<bool>* excluded(const BaExclusions* e) { return e ? &e->line_out : nullptr; }
};

struct ObsRef {
  int obs;      // index into the problem's observation array
  int kf;       // keyframe
  int cam;      // free camera slot, -1 when the keyframe is fixed
  double info;  // whitening weight
};

// The active observations of one landmark kind, grouped by free landmark (CSR), and the
// per-landmark blocks of the current linearisation.
// The per-observation blocks W of a local BA take ~10 MB; allocated afresh for every call they
// come back as new pages, and the page faults cost 3-4 % of the solve. A thread keeps the
// storage of its last solves (local mapping runs one BA per keyframe) up to kKeepBytes.
template <class T>
class PooledVector {
 public:
  PooledVector() = default;
  PooledVector(PooledVector&& o) noexcept : v_(std::move(o.v_)) {}
  PooledVector& operator=(PooledVector&& o) noexcept {
    if (this != &o) {
      release();
      v_ = std::move(o.v_);
    }
    return *this;
  }
  PooledVector(const PooledVector&) = delete;
  PooledVector& operator=(const PooledVector&) = delete;
  ~PooledVector() { release(); }

  void resize(std::size_t n) {
    if (v_.capacity() < n) {
      auto& spare = pool();
      // Take a stored buffer if one is large enough (the last is the most recent).
      for (auto it = spare.rbegin(); it != spare.rend(); ++it) {
        if (it->capacity() >= n) {
          v_.swap(*it);
          spare.erase(std::next(it).base());
          break;
        }
      }
    }
    v_.resize(n);
  }
  void swap(PooledVector& o) noexcept { v_.swap(o.v_); }
  T& operator[](std::size_t i) { return v_[i]; }
  const T& operator[](std::size_t i) const { return v_[i]; }
  std::size_t size() const { return v_.size(); }

 private:
  static constexpr std::size_t kKeepBytes = std::size_t{64} << 20;
  static constexpr std::size_t kKeepBuffers = 4;
  static std::vector<std::vector<T>>& pool() {
    thread_local std::vector<std::vector<T>> spare;
    return spare;
  }
  void release() {
    if (v_.capacity() == 0 || v_.capacity() * sizeof(T) > kKeepBytes) return;
    auto& spare = pool();
    if (spare.size() >= kKeepBuffers) spare.erase(spare.begin());
    v_.clear();
    spare.push_back(std::move(v_));
    v_ = {};
  }
  std::vector<T> v_;
};

template <class Kind>
struct Groups {
  static constexpr int N = Kind::N;
  using MatN = Eigen::Matrix<double, N, N>;
  using VecN = Eigen::Matrix<double, N, 1>;
  using Mat6N = Eigen::Matrix<double, 6, N>;

  std::vector<int> landmark;  // problem index of each free slot
  std::vector<int> begin;     // slot i owns refs [begin[i], begin[i + 1])
  std::vector<ObsRef> refs;
  std::vector<ObsRef> fixed;  // observations of fixed landmarks: camera blocks and cost only
  PooledVector<Mat6N> W;      // per ref: w Jc' Jl
  std::vector<MatN> H, Hinv;  // per slot: Jl' w Jl and the inverse of its damped version
  std::vector<VecN> g, dx;    // per slot: gradient and step
  // The linearisation at the candidate state, swapped in when the step is accepted.
  PooledVector<Mat6N> W_next;
  std::vector<MatN> H_next;
  std::vector<VecN> g_next;
  int max_group = 0;

  int slots() const { return static_cast<int>(landmark.size()); }
  void swap_in_next() {
    W.swap(W_next);
    H.swap(H_next);
    g.swap(g_next);
  }
};

template <class Kind>
Groups<Kind> make_groups(const BaProblem& p, const BaOptions& opt, const std::vector<bool>* out,
                         const std::vector<int>& cam_of_kf) {
  Groups<Kind> G;
  const auto& obs = Kind::observations(p);
  std::vector<int> slot_of(Kind::count(p), -1), counts;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    if (out && (*out)[k]) continue;
    const int l = Kind::landmark(obs[k]);
    if (Kind::fixed(p, l)) {
      // The information (a pow per observation) only where the reference is kept.
      G.fixed.push_back({static_cast<int>(k), obs[k].keyframe,
                         cam_of_kf[static_cast<std::size_t>(obs[k].keyframe)], Kind::info(obs[k], opt)});
      continue;
    }
    int& slot = slot_of[static_cast<std::size_t>(l)];
    if (slot < 0) {
      slot = G.slots();
      G.landmark.push_back(l);
      counts.push_back(0);
    }
    ++counts[static_cast<std::size_t>(slot)];
  }
  G.begin.assign(counts.size() + 1, 0);
  for (std::size_t i = 0; i < counts.size(); ++i) {
    G.begin[i + 1] = G.begin[i] + counts[i];
    G.max_group = std::max(G.max_group, counts[i]);
  }
  G.refs.resize(static_cast<std::size_t>(G.begin.back()));
  std::vector<int> fill(G.begin.begin(), G.begin.end() - 1);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    if (out && (*out)[k]) continue;
    const int l = Kind::landmark(obs[k]);
    if (Kind::fixed(p, l)) continue;
    const int slot = slot_of[static_cast<std::size_t>(l)];
    G.refs[static_cast<std::size_t>(fill[static_cast<std::size_t>(slot)]++)] = {
        static_cast<int>(k), obs[k].keyframe, cam_of_kf[static_cast<std::size_t>(obs[k].keyframe)],
        Kind::info(obs[k], opt)};
  }
  G.W.resize(G.refs.size());
  G.W_next.resize(G.refs.size());
  G.H.resize(counts.size());
  G.H_next.resize(counts.size());
  G.Hinv.resize(counts.size());
  G.g.resize(counts.size());
  G.g_next.resize(counts.size());
  G.dx.resize(counts.size());
  return G;
}

// Per-thread sums over observations: the camera part of the normal equations (upper block
// triangle of H is used) and the robust cost.
struct Accumulator {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  double rho = 0.0;  // sum of rho: twice the cost
  int failures = 0;  // observations behind a camera, or landmark blocks that failed to factor
  // W L^-1 per ref of the landmark being eliminated (points, lines).
  std::vector<Eigen::Matrix<double, 6, 3>> Y3;
  std::vector<Eigen::Matrix<double, 6, 6>> Y6;
  std::vector<int> cams;  // camera slot per ref of that landmark

  Accumulator(int n_cams, int max_group)
      : H(Eigen::MatrixXd::Zero(6 * n_cams, 6 * n_cams)),
        g(Eigen::VectorXd::Zero(6 * n_cams)),
        Y3(static_cast<std::size_t>(max_group)),
        Y6(static_cast<std::size_t>(max_group)),
        cams(static_cast<std::size_t>(max_group)) {}
  auto& scratch(std::integral_constant<int, 3>) { return Y3; }
  auto& scratch(std::integral_constant<int, 6>) { return Y6; }
  void add(const Accumulator& o) {
    H += o.H;
    g += o.g;
    rho += o.rho;
    failures += o.failures;
  }
};

// Work items of a pass over all observations: the free point slots, the free line slots, then the
// observations of fixed points and of fixed lines, one item each.
template <class PointGroups, class LineGroups, class SlotFn, class FixedFn>
void dispatch(int item, PointGroups& points, LineGroups& lines, const SlotFn& slot_fn,
              const FixedFn& fixed_fn) {
  const int np = points.slots(), nl = lines.slots();
  const int nfp = static_cast<int>(points.fixed.size());
  if (item < np) return slot_fn(points, item);
  item -= np;
  if (item < nl) return slot_fn(lines, item);
  item -= nl;
  if (item < nfp) return fixed_fn(points, item);
  fixed_fn(lines, item - nfp);
}

class SchurLm {
 public:
  SchurLm(const geometry::StereoCamera& cam, const BaProblem& p, const BaOptions& opt,
          const BaPassSpec& spec, BaState* s)
      : ctx_{cam, opt, spec.robust}, p_(p), opt_(opt), spec_(spec), s_(s),
        threads_(std::max(1, opt.num_threads)) {
    if (threads_ > 1) pool_ = std::make_unique<core::WorkerPool>(threads_, "plslam-ba");
    build(spec.excluded);
  }

  BaPassSummary run();

 private:
  void build(const BaExclusions* excluded);
  int max_group() const { return std::max(points_.max_group, lines_.max_group); }
  int work_items() const {
    return points_.slots() + lines_.slots() + static_cast<int>(points_.fixed.size()) +
           static_cast<int>(lines_.fixed.size());
  }
  // Runs body(item, acc) over [0, n) and returns the sum of the accumulators. With threads, [0, n)
  // is cut into one fixed range per thread, each with its own accumulator, summed in range order:
  // the result depends on the thread count but never on the scheduling.
  template <class Body>
  Accumulator accumulate(int n, const Body& body) const;

  // Linearises at `poses`, `extra` and the landmarks (plus their step when with_step) into the
  // *_next buffers; returns 2x the cost, infinity when an observation is behind its camera.
  double linearize(const std::vector<SE3>& poses, const std::vector<Vector9d>& extra, bool with_step);
  // The keyframe factors' share of the reduced system, added to C_next_ and gc_next_ (grown to
  // take the extra states); returns their sum of squared residuals.
  double linearize_keyframe_factors(const std::vector<SE3>& poses, const std::vector<Vector9d>& extra);
  Eigen::Index pose_unknowns() const { return 6 * static_cast<Eigen::Index>(kf_of_cam_.size()); }
  void swap_in_next();
  bool solve(double lambda);
  double model_decrease(double lambda) const;
  void apply(std::vector<SE3> poses, std::vector<Vector9d> extra);
  double state_norm() const;
  double step_norm() const;
  BaExclusions exclusions_with_invalid() const;

  template <class Kind>
  void linearize_slot(Groups<Kind>& G, int i, const std::vector<SE3>& poses, bool with_step,
                      Accumulator& acc) const;
  template <class Kind>
  void linearize_fixed(const Groups<Kind>& G, int k, const std::vector<SE3>& poses,
                       Accumulator& acc) const;
  template <class Kind>
  void eliminate_slot(Groups<Kind>& G, int i, double lambda, Accumulator& acc) const;
  template <class Kind>
  void back_substitute(Groups<Kind>& G, int i) const;

  Context ctx_;
  const BaProblem& p_;
  const BaOptions& opt_;
  const BaPassSpec& spec_;
  BaState* s_;
  int threads_;
  SchurKernelImpl kernel_ = best_schur_kernel();
  mutable std::unique_ptr<core::WorkerPool> pool_;  // run() is non-const

  std::vector<int> cam_of_kf_;
  std::vector<int> kf_of_cam_;
  std::vector<int> extra_of_kf_;  // extra-state slot of a free keyframe in a keyframe factor, else -1
  std::vector<int> kf_of_extra_;
  Groups<PointKind> points_;
  Groups<LineKind> lines_;
  std::vector<Eigen::Matrix3d> line_along_;  // per line slot: d d' of its direction (zero: collapsed)
  // Current linearisation (camera part) and step.
  Eigen::MatrixXd C_, C_next_;  // block diagonal, 6x6 per free camera
  Eigen::VectorXd gc_, gc_next_, dc_;
  double rho_ = 0.0;  // 2x cost at the current state
};

void SchurLm::build(const BaExclusions* excluded) {
  // A keyframe gets a camera slot when it is free and observed by an active observation.
  cam_of_kf_.assign(p_.keyframes.size(), -1);
  kf_of_cam_.clear();
  const auto mark = [&](int kf) {
    const auto k = static_cast<std::size_t>(kf);
    if (p_.keyframes[k].fixed || cam_of_kf_[k] >= 0) return;
    cam_of_kf_[k] = static_cast<int>(kf_of_cam_.size());
    kf_of_cam_.push_back(kf);
  };
  for (std::size_t k = 0; k < p_.point_observations.size(); ++k) {
    if (!excluded || !excluded->point_out[k]) mark(p_.point_observations[k].keyframe);
  }
  for (std::size_t k = 0; k < p_.line_observations.size(); ++k) {
    if (!excluded || !excluded->line_out[k]) mark(p_.line_observations[k].keyframe);
  }
  // After the observed ones, so that a problem without factors keeps its slots.
  extra_of_kf_.assign(p_.keyframes.size(), -1);
  kf_of_extra_.clear();
  for (const auto& f : p_.keyframe_factors) {
    for (const int kf : f->keyframes()) {
      mark(kf);
      const auto k = static_cast<std::size_t>(kf);
      if (p_.keyframes[k].fixed || extra_of_kf_[k] >= 0) continue;
      extra_of_kf_[k] = static_cast<int>(kf_of_extra_.size());
      kf_of_extra_.push_back(kf);
    }
  }
  points_ = make_groups<PointKind>(p_, opt_, PointKind::excluded(excluded), cam_of_kf_);
  lines_ = make_groups<LineKind>(p_, opt_, LineKind::excluded(excluded), cam_of_kf_);
  // Each line's direction at the start of the pass: its endpoints move only across it.
  line_along_.clear();
  for (const int l : lines_.landmark) {
    const Vector6d& L = s_->lines[static_cast<std::size_t>(l)];
    const Eigen::Vector3d d = L.tail<3>() - L.head<3>();
    line_along_.push_back(d.norm() > 1e-9 ? Eigen::Matrix3d(d.normalized() * d.normalized().transpose())
                                          : Eigen::Matrix3d::Zero());
  }
}

template <class Body>
Accumulator SchurLm::accumulate(int n, const Body& body) const {
  const int n_cams = static_cast<int>(kf_of_cam_.size());
  if (!pool_) {
    Accumulator acc(n_cams, max_group());
    for (int i = 0; i < n; ++i) body(i, acc);
    return acc;
  }
  const int chunks = threads_;
  std::vector<Accumulator> partial(static_cast<std::size_t>(chunks), Accumulator(n_cams, max_group()));
  pool_->run(chunks, [&](int c) {
    Accumulator& acc = partial[static_cast<std::size_t>(c)];
    const int end = core::chunk_begin(n, chunks, c + 1);
    for (int i = core::chunk_begin(n, chunks, c); i < end; ++i) body(i, acc);
  });
  Accumulator total(n_cams, 0);
  for (const Accumulator& acc : partial) total.add(acc);
  return total;
}

template <class Kind>
void SchurLm::linearize_slot(Groups<Kind>& G, int i, const std::vector<SE3>& poses,
                             bool with_step, Accumulator& acc) const {
  const auto si = static_cast<std::size_t>(i);
  const auto& obs = Kind::observations(p_);
  typename Kind::Vec X = Kind::values(*s_)[static_cast<std::size_t>(G.landmark[si])];
  if (with_step) X += G.dx[si];
  auto& H = G.H_next[si];
  auto& g = G.g_next[si];
  H.setZero();
  g.setZero();
  for (int k = G.begin[si]; k < G.begin[si + 1]; ++k) {
    const ObsRef& ref = G.refs[static_cast<std::size_t>(k)];
    const SE3& T = poses[static_cast<std::size_t>(ref.kf)];
    if constexpr (std::is_same_v<Kind, PointKind>) {
      PointLinearization lin;
      if (!linearize_point(ctx_, obs[static_cast<std::size_t>(ref.obs)], ref.info, T, X, lin)) {
        ++acc.failures;
        continue;
      }
      acc.rho += lin.rho;
      H.noalias() += T.rotation().transpose().lazyProduct(lin.BR);
      g.noalias() += T.rotation().transpose() * lin.a;
      if (ref.cam < 0) continue;
      add_pose_normal_equations(lin.B, lin.a, lin.Xc, acc.H.template block<6, 6>(6 * ref.cam, 6 * ref.cam),
                                acc.g.template segment<6>(6 * ref.cam));
      auto& W = G.W_next[static_cast<std::size_t>(k)];
      W.template topRows<3>() = lin.BR;
      for (int j = 0; j < 3; ++j) W.template block<3, 1>(3, j) = lin.Xc.cross(lin.BR.col(j));
    } else {
      LineLinearization lin;
      if (!linearize_line(ctx_, obs[static_cast<std::size_t>(ref.obs)], ref.info, T, X, lin)) {
        ++acc.failures;
        continue;
      }
      acc.rho += lin.rho;
      for (int x = 0; x < 2; ++x) {
        H.template block<3, 3>(3 * x, 3 * x).noalias() += T.rotation().transpose().lazyProduct(lin.BR[x]);
        g.template segment<3>(3 * x).noalias() += T.rotation().transpose() * lin.a[x];
      }
      if (ref.cam < 0) continue;
      auto& W = G.W_next[static_cast<std::size_t>(k)];
      for (int x = 0; x < 2; ++x) {
        add_pose_normal_equations(lin.B[x], lin.a[x], lin.Xc[x],
                                  acc.H.template block<6, 6>(6 * ref.cam, 6 * ref.cam),
                                  acc.g.template segment<6>(6 * ref.cam));
        W.template block<3, 3>(0, 3 * x) = lin.BR[x];
        for (int j = 0; j < 3; ++j) {
          W.template block<3, 1>(3, 3 * x + j) = lin.Xc[x].cross(lin.BR[x].col(j));
        }
      }
    }
  }
}

template <class Kind>
void SchurLm::linearize_fixed(const Groups<Kind>& G, int k, const std::vector<SE3>& poses,
                              Accumulator& acc) const {
  const ObsRef& ref = G.fixed[static_cast<std::size_t>(k)];
  const auto& o = Kind::observations(p_)[static_cast<std::size_t>(ref.obs)];
  const auto& X = Kind::values(*s_)[static_cast<std::size_t>(Kind::landmark(o))];
  const SE3& T = poses[static_cast<std::size_t>(ref.kf)];
  if constexpr (std::is_same_v<Kind, PointKind>) {
    PointLinearization lin;
    if (!linearize_point(ctx_, o, ref.info, T, X, lin)) {
      ++acc.failures;
      return;
    }
    acc.rho += lin.rho;
    if (ref.cam < 0) return;
    add_pose_normal_equations(lin.B, lin.a, lin.Xc, acc.H.template block<6, 6>(6 * ref.cam, 6 * ref.cam),
                              acc.g.template segment<6>(6 * ref.cam));
  } else {
    LineLinearization lin;
    if (!linearize_line(ctx_, o, ref.info, T, X, lin)) {
      ++acc.failures;
      return;
    }
    acc.rho += lin.rho;
    if (ref.cam < 0) return;
    for (int x = 0; x < 2; ++x) {
      add_pose_normal_equations(lin.B[x], lin.a[x], lin.Xc[x],
                                acc.H.template block<6, 6>(6 * ref.cam, 6 * ref.cam),
                                acc.g.template segment<6>(6 * ref.cam));
    }
  }
}

double SchurLm::linearize_keyframe_factors(const std::vector<SE3>& poses, const std::vector<Vector9d>& extra) {
  const Eigen::Index n6 = pose_unknowns();
  const Eigen::Index n = n6 + 9 * static_cast<Eigen::Index>(kf_of_extra_.size());
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  C.topLeftCorner(n6, n6) = C_next_;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  g.head(n6) = gc_next_;
  double sq = 0.0;
  std::vector<SE3> T;
  std::vector<Vector9d> x;
  std::vector<Eigen::Index> at;  // per factor column block: its row in the reduced system, -1 fixed
  Eigen::MatrixXd J;
  for (const auto& f : p_.keyframe_factors) {
    const auto kfs = f->keyframes();
    T.clear();
    x.clear();
    at.clear();
    for (const int kf : kfs) {
      const auto k = static_cast<std::size_t>(kf);
      T.push_back(poses[k]);
      x.push_back(extra[k]);
      // Pose columns, then the extra state's (a factor's keyframe with a camera slot has one).
      const int c = cam_of_kf_[k];
      at.push_back(c >= 0 ? 6 * static_cast<Eigen::Index>(c) : -1);
      at.push_back(c >= 0 ? n6 + 9 * static_cast<Eigen::Index>(extra_of_kf_[k]) : -1);
    }
    const Eigen::VectorXd r = f->evaluate(T, x, &J);
    if (!r.allFinite() || !J.allFinite()) return std::numeric_limits<double>::infinity();
    sq += r.squaredNorm();
    const auto width = [](std::size_t b) { return b % 2 == 0 ? 6 : 9; };
    const auto col = [](std::size_t b) { return static_cast<Eigen::Index>(15 * (b / 2) + (b % 2 == 0 ? 0 : 6)); };
    for (std::size_t a = 0; a < at.size(); ++a) {
      if (at[a] < 0) continue;
      const auto Ja = J.middleCols(col(a), width(a));
      g.segment(at[a], width(a)).noalias() += Ja.transpose() * r;
      for (std::size_t b = 0; b < at.size(); ++b) {
        if (at[b] < 0) continue;
        C.block(at[a], at[b], width(a), width(b)).noalias() += Ja.transpose() * J.middleCols(col(b), width(b));
      }
    }
  }
  C_next_ = std::move(C);
  gc_next_ = std::move(g);
  return sq;
}

double SchurLm::linearize(const std::vector<SE3>& poses, const std::vector<Vector9d>& extra, bool with_step) {
  Accumulator acc = accumulate(work_items(), [&](int item, Accumulator& a) {
    dispatch(
        item, points_, lines_, [&](auto& G, int i) { linearize_slot(G, i, poses, with_step, a); },
        [&](const auto& G, int k) { linearize_fixed(G, k, poses, a); });
  });
  C_next_ = std::move(acc.H);
  gc_next_ = std::move(acc.g);
  if (acc.failures > 0) return std::numeric_limits<double>::infinity();
  if (p_.keyframe_factors.empty()) return acc.rho;
  return acc.rho + linearize_keyframe_factors(poses, extra);
}

void SchurLm::swap_in_next() {
  C_.swap(C_next_);
  gc_.swap(gc_next_);
  points_.swap_in_next();
  lines_.swap_in_next();
}

template <class Kind>
void SchurLm::eliminate_slot(Groups<Kind>& G, int i, double lambda, Accumulator& acc) const {
  constexpr int N = Kind::N;
  const auto si = static_cast<std::size_t>(i);
  Eigen::Matrix<double, N, N> Hd = G.H[si];
  for (int j = 0; j < N; ++j) Hd(j, j) += lambda * damping_diagonal(G.H[si](j, j));
  if constexpr (N == 6) {
    // A line's endpoints are free along the 3D line, and the diagonal damping alone (lambda down
    // to 1e-12) let them run there on the noise in the gradient: both converged to the one point
    // that fits the observed planes best, and the segment collapsed. A stiffness along the line's
    // direction, 1e9 times the block's constrained ones, holds them: the step moves each
    // endpoint only across the line's direction at the start of the pass, as the Ceres backend's
    // LineEndpointsManifold does.
    const Eigen::Matrix3d& dd = line_along_[si];
    constexpr double kAlongLine = 1e9;
    Hd.template topLeftCorner<3, 3>() += kAlongLine * std::max(G.H[si].template topLeftCorner<3, 3>().trace(), kMinDiagonal) * dd;
    Hd.template bottomRightCorner<3, 3>() += kAlongLine * std::max(G.H[si].template bottomRightCorner<3, 3>().trace(), kMinDiagonal) * dd;
  }
  if (!invert_spd(Hd, &G.Hinv[si])) {
    ++acc.failures;
    return;
  }
  const auto& Hinv = G.Hinv[si];
  const int b = G.begin[si], e = G.begin[si + 1];
  auto& Ys = acc.scratch(std::integral_constant<int, N>());
  // Y_a = W_a L^-1 once per observation; the kernel then subtracts Y_a W_c' for every pair
  // into the upper block triangle of S.
  for (int a = b; a < e; ++a) {
    const ObsRef& ra = G.refs[static_cast<std::size_t>(a)];
    acc.cams[static_cast<std::size_t>(a - b)] = ra.cam;
    if (ra.cam < 0) continue;
    auto& Y = Ys[static_cast<std::size_t>(a - b)];
    Y.noalias() = G.W[static_cast<std::size_t>(a)].lazyProduct(Hinv);
    acc.g.template segment<6>(6 * ra.cam).noalias() -= Y * G.g[si];
  }
  if (e > b) {
    schur_landmark_update(kernel_, N, e - b, acc.cams.data(), Ys.front().data(),
                          G.W[static_cast<std::size_t>(b)].data(), acc.H.data(), acc.H.rows());
  }
}

template <class Kind>
void SchurLm::back_substitute(Groups<Kind>& G, int i) const {
  const auto si = static_cast<std::size_t>(i);
  Eigen::Matrix<double, Kind::N, 1> rhs = G.g[si];
  for (int a = G.begin[si]; a < G.begin[si + 1]; ++a) {
    const int c = G.refs[static_cast<std::size_t>(a)].cam;
    if (c >= 0) rhs.noalias() += G.W[static_cast<std::size_t>(a)].transpose() * dc_.segment<6>(6 * c);
  }
  G.dx[si].noalias() = -(G.Hinv[si] * rhs);
}

bool SchurLm::solve(double lambda) {
  const int n_slots = points_.slots() + lines_.slots();
  Accumulator acc = accumulate(n_slots, [this, lambda](int item, Accumulator& a) {
    if (item < points_.slots()) {
      eliminate_slot(points_, item, lambda, a);
    } else {
      eliminate_slot(lines_, item - points_.slots(), lambda, a);
    }
  });
  if (acc.failures > 0) return false;
  const auto n = C_.rows();
  if (n > 0) {
    // The kernel fills the upper block triangle; the factorisation reads only that. LLT rather
    // than LDLT: Eigen's LLT is blocked (matrix-matrix updates), its LDLT is rank-1 updates only,
    // which made the factorisation a third of a 150-keyframe global BA's CPU. The damped system is
    // positive definite; when it is not, the step fails and LM damps more, as for a landmark.
    // (The landmarks touch only the pose unknowns, the first 6 n_cams.)
    const bool extra = n > acc.H.rows();
    Eigen::MatrixXd S = extra ? C_ : C_ + acc.H;
    if (extra) S.topLeftCorner(acc.H.rows(), acc.H.cols()) += acc.H;
    for (Eigen::Index j = 0; j < n; ++j) S(j, j) += lambda * damping_diagonal(C_(j, j));
    const Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> llt(S);
    if (llt.info() != Eigen::Success) return false;
    if (extra) {
      Eigen::VectorXd rhs = -gc_;
      rhs.head(acc.g.size()) -= acc.g;
      dc_ = llt.solve(rhs);
    } else {
      dc_ = llt.solve(-(gc_ + acc.g));
    }
    if (!dc_.allFinite()) return false;
  } else {
    dc_.resize(0);
  }
  bool finite = true;
  for (int i = 0; i < points_.slots(); ++i) {
    back_substitute(points_, i);
    finite = finite && points_.dx[static_cast<std::size_t>(i)].allFinite();
  }
  for (int i = 0; i < lines_.slots(); ++i) {
    back_substitute(lines_, i);
    finite = finite && lines_.dx[static_cast<std::size_t>(i)].allFinite();
  }
  return finite;
}

// L(0) - L(dx) of the quadratic model; with (H + lambda D) dx = -g this is
// (lambda dx' D dx - g' dx) / 2, all blocks summed.
double SchurLm::model_decrease(double lambda) const {
  double sum = 0.0;
  for (Eigen::Index j = 0; j < dc_.size(); ++j) {
    sum += lambda * damping_diagonal(C_(j, j)) * dc_(j) * dc_(j) - gc_(j) * dc_(j);
  }
  const auto add = [&](const auto& G) {
    for (std::size_t i = 0; i < G.dx.size(); ++i) {
      for (int j = 0; j < G.N; ++j) {
        sum += lambda * damping_diagonal(G.H[i](j, j)) * G.dx[i](j) * G.dx[i](j) -
               G.g[i](j) * G.dx[i](j);
      }
    }
  };
  add(points_);
  add(lines_);
  return 0.5 * sum;
}

void SchurLm::apply(std::vector<SE3> poses, std::vector<Vector9d> extra) {
  s_->poses = std::move(poses);
  s_->extra = std::move(extra);
  const auto add = [&](auto& G, auto& values) {
    for (std::size_t i = 0; i < G.dx.size(); ++i) {
      values[static_cast<std::size_t>(G.landmark[i])] += G.dx[i];
    }
  };
  add(points_, s_->points);
  add(lines_, s_->lines);
}

double SchurLm::state_norm() const {
  double sq = 0.0;
  for (const int kf : kf_of_cam_) {
    sq += s_->poses[static_cast<std::size_t>(kf)].translation().squaredNorm() + 1.0;  // + |q|^2
  }
  for (const int kf : kf_of_extra_) sq += s_->extra[static_cast<std::size_t>(kf)].squaredNorm();
  for (const int l : points_.landmark) sq += s_->points[static_cast<std::size_t>(l)].squaredNorm();
  for (const int l : lines_.landmark) sq += s_->lines[static_cast<std::size_t>(l)].squaredNorm();
  return std::sqrt(sq);
}

double SchurLm::step_norm() const {
  double sq = dc_.squaredNorm();
  for (const auto& d : points_.dx) sq += d.squaredNorm();
  for (const auto& d : lines_.dx) sq += d.squaredNorm();
  return std::sqrt(sq);
}

BaExclusions SchurLm::exclusions_with_invalid() const { return with_behind_camera(p_, spec_, *s_); }

BaPassSummary SchurLm::run() {
  BaPassSummary out;
  int dropped = 0;
  rho_ = linearize(s_->poses, s_->extra, false);
  if (!std::isfinite(rho_)) {
    // Observations behind their camera at the start are left out of this pass (Ceres would
    // refuse to start); the final gate flags them as outliers.
    const BaExclusions ex = exclusions_with_invalid();
    for (const bool b : ex.point_out) dropped += b;
    for (const bool b : ex.line_out) dropped += b;
    build(&ex);
    rho_ = linearize(s_->poses, s_->extra, false);
  }
  swap_in_next();
  out.initial_cost = out.final_cost = 0.5 * rho_;
  if (points_.refs.empty() && lines_.refs.empty() && points_.fixed.empty() && lines_.fixed.empty() &&
      p_.keyframe_factors.empty()) {
    out.message = "no observations";  // not usable: nothing was optimised
    return out;
  }
  double lambda = kInitialLambda, nu = 2.0;
  int accepted = 0;
  const char* why = "iteration limit";
  while (out.iterations < spec_.iterations) {
    if (opt_.abort && opt_.abort->load()) {
      why = "aborted";
      break;
    }
    if (gc_.size() == 0 && points_.slots() == 0 && lines_.slots() == 0) {
      why = "nothing free";
      break;
    }
    double gmax = gc_.size() > 0 ? gc_.cwiseAbs().maxCoeff() : 0.0;
    for (const auto& g : points_.g) gmax = std::max(gmax, g.cwiseAbs().maxCoeff());
    for (const auto& g : lines_.g) gmax = std::max(gmax, g.cwiseAbs().maxCoeff());
    if (gmax <= kGradientTolerance) {
      why = "gradient tolerance";
      break;
    }
    ++out.iterations;
    if (!solve(lambda)) {  // a damped block was not positive definite: damp more
      lambda *= nu;
      nu *= 2.0;
      if (lambda > kMaxLambda) {
        why = "damping limit";
        break;
      }
      continue;
    }
    if (step_norm() <= kParameterTolerance * (state_norm() + kParameterTolerance)) {
      why = "parameter tolerance";
      break;
    }
    std::vector<SE3> poses = s_->poses;
    for (std::size_t c = 0; c < kf_of_cam_.size(); ++c) {
      auto& T = poses[static_cast<std::size_t>(kf_of_cam_[c])];
      T = SE3::exp(dc_.segment<6>(6 * static_cast<Eigen::Index>(c))) * T;
    }
    std::vector<Vector9d> extra = s_->extra;
    for (std::size_t e = 0; e < kf_of_extra_.size(); ++e) {
      extra[static_cast<std::size_t>(kf_of_extra_[e])] += dc_.segment<9>(pose_unknowns() + 9 * static_cast<Eigen::Index>(e));
    }
    const double rho_new = linearize(poses, extra, true);  // the next linearisation if accepted
    const double decrease = 0.5 * (rho_ - rho_new);
    const double model = model_decrease(lambda);
    const double ratio = decrease / model;
    const bool converged = std::isfinite(rho_new) && std::abs(decrease) <= opt_.function_tolerance * 0.5 * rho_;
    if (std::isfinite(rho_new) && model > 0.0 && ratio > kMinRelativeDecrease) {
      apply(std::move(poses), std::move(extra));
      swap_in_next();
      rho_ = rho_new;
      ++accepted;
      lambda = std::max(kMinLambda, lambda * std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * ratio - 1.0, 3)));
      nu = 2.0;
    } else {
      lambda *= nu;
      nu *= 2.0;
    }
    if (converged) {
      why = "function tolerance";
      break;
    }
    if (lambda > kMaxLambda) {
      why = "damping limit";
      break;
    }
  }
  out.final_cost = 0.5 * rho_;
  out.usable = std::isfinite(out.final_cost);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Schur LM: %d iterations (%d accepted), cost %.6e -> %.6e, lambda %.1e, %s; "
                "%d cameras, %d points, %d lines, %d observations dropped behind a camera%s",
                out.iterations, accepted, out.initial_cost, out.final_cost, lambda, why,
                static_cast<int>(kf_of_cam_.size()), points_.slots(), lines_.slots(), dropped,
                p_.keyframe_factors.empty() ? "" : (", " + std::to_string(p_.keyframe_factors.size()) + " keyframe factors").c_str());
  out.message = buf;
  return out;
}

}  // namespace

BaPassSummary schur_lm_ba_pass(const geometry::StereoCamera& cam, const BaProblem& p,
                               const BaOptions& opt, const BaPassSpec& spec, BaState* s) {
  return SchurLm(cam, p, opt, spec, s).run();
}

}  // namespace plslam::optim
