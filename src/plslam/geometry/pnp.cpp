#include "plslam/geometry/pnp.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "plslam/core/error.h"

namespace plslam::geometry {

PnpResult solve_pnp_ransac(const StereoCamera& cam, const std::vector<Eigen::Vector3d>& world,
                           const std::vector<Eigen::Vector2d>& pixels, const PnpOptions& options) {
  if (world.size() != pixels.size()) {
    throw InputError("", "solve_pnp_ransac: 3D and 2D point counts differ");
  }
  PnpResult result;
  if (world.size() < 4) return result;
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  obj.reserve(world.size());
  img.reserve(world.size());
  for (std::size_t i = 0; i < world.size(); ++i) {
    obj.emplace_back(world[i].x(), world[i].y(), world[i].z());
    img.emplace_back(pixels[i].x(), pixels[i].y());
  }
  const cv::Matx33d K(cam.fx(), 0, cam.cx(), 0, cam.fy(), cam.cy(), 0, 0, 1);
  cv::Mat rvec, tvec;
  cv::UsacParams usac;
  usac.maxIterations = options.max_iterations;
  usac.threshold = options.reprojection_error_px;
  usac.confidence = options.confidence;
  usac.randomGeneratorState = static_cast<int>(options.seed & 0x7fffffffu);
  usac.sampler = cv::SAMPLING_UNIFORM;
  usac.isParallel = false;  // a parallel USAC would not reproduce
  cv::Mat inlier_mat;
  bool ok = false;
  try {
    ok = cv::solvePnPRansac(obj, img, K, cv::noArray(), rvec, tvec, inlier_mat, usac);
  } catch (const cv::Exception&) {
    ok = false;  // USAC throws on degenerate input (all points collinear, too few distinct)
  }
  std::vector<int> inliers;
  if (ok) inlier_mat.reshape(1, 1).copyTo(inliers);
  if (!ok || static_cast<int>(inliers.size()) < std::max(options.min_inliers, 4)) return result;

  // Levenberg-Marquardt on the inliers only, starting from the EPnP estimate.
  std::vector<cv::Point3d> obj_in;
  std::vector<cv::Point2d> img_in;
  for (const int i : inliers) {
    obj_in.push_back(obj[static_cast<std::size_t>(i)]);
    img_in.push_back(img[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(obj_in, img_in, K, cv::noArray(), rvec, tvec);

  cv::Mat Rcv;
  cv::Rodrigues(rvec, Rcv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(Rcv, R);
  cv::cv2eigen(tvec, t);
  result.success = true;
  result.T_cw = SE3(Eigen::Quaterniond(R), t);
  result.inliers = std::move(inliers);
  return result;
}

}  // namespace plslam::geometry
