#include "plslam/optim/pose_only.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "plslam/optim/pose_rounds.h"
#include "plslam/optim/pose_terms.h"

namespace plslam::optim {
namespace {

using geometry::Matrix6d;
using geometry::SE3;
using geometry::Vector6d;

}  // namespace

PoseOnlyResult optimize_pose(const geometry::StereoCamera& cam, const SE3& T_cw_init,
                             const std::vector<PosePointTerm>& points,
                             const std::vector<PoseLineTerm>& lines,
                             const PoseOnlyOptions& options) {
  const PoseTerms p(cam, points, lines, options);

  PoseOnlyResult res;
  const SE3 T = run_pose_rounds<6>(
      p, options, T_cw_init, res,
      [&](const SE3& x, bool robust, Matrix6d* H, Vector6d* g) {
        H->setZero();
        g->setZero();
        return p.evaluate(x, res.point_outlier, res.line_outlier, robust, H, g);
      },
      [](const SE3& x, const Vector6d& delta) { return SE3::exp(delta) * x; }, [](const SE3& x) { return x; });
  res.T_cw = T;
  if (options.covariance) res.covariance = p.covariance(T, res.point_outlier, res.line_outlier);
  return res;
}

}  // namespace plslam::optim
