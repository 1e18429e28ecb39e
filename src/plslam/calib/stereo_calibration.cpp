#include "plslam/calib/stereo_calibration.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "plslam/calib/rig_refinement.h"
#include "plslam/core/error.h"

namespace plslam::calib {
namespace {

constexpr int kMinViewsPerCamera = 6;
constexpr int kMinStereoViews = 4;
const cv::TermCriteria kCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);

struct ViewData {
  int frame = 0;
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
};

ViewData view_data(int frame, const BoardDetection& d, const std::vector<cv::Point3f>& corners) {
  ViewData v;
  v.frame = frame;
  for (std::size_t i = 0; i < d.ids.size(); ++i) {
    v.object.push_back(corners.at(static_cast<std::size_t>(d.ids[i])));
    v.image.push_back(d.pixels[i]);
  }
  return v;
}

// Corners that all lie near one line of the board (one row seen, or two at a grazing angle) fix
// no homography: OpenCV's fisheye initialisation asserts on them. The spread across the board's
// thinner direction must reach half a square.
bool spans_the_board(const ViewData& v, double square_m) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : v.object) mean += Eigen::Vector2d(p.x, p.y);
  mean /= static_cast<double>(v.object.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : v.object) {
    const Eigen::Vector2d d = Eigen::Vector2d(p.x, p.y) - mean;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(v.object.size());
  const double thinnest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues()(0);
  return std::sqrt(std::max(thinnest, 0.0)) >= 0.5 * square_m;
}

std::vector<int> cells_of(const ViewData& v, cv::Size size, const CalibrationOptions& o) {
  std::vector<int> cells;
  for (const auto& p : v.image) {
    const int cx = std::clamp(static_cast<int>(p.x * o.coverage_cells_x / size.width), 0, o.coverage_cells_x - 1);
    const int cy = std::clamp(static_cast<int>(p.y * o.coverage_cells_y / size.height), 0, o.coverage_cells_y - 1);
    cells.push_back(cy * o.coverage_cells_x + cx);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

// Greedy: the view covering the most cells no chosen view covers yet (ties: more corners), until
// max_views; once every cell is covered, the count restarts, so cells get covered again.
std::vector<ViewData> select_for_coverage(std::vector<ViewData> views, cv::Size size, const CalibrationOptions& o) {
  if (static_cast<int>(views.size()) <= o.max_views) return views;
  std::vector<ViewData> chosen;
  std::vector<int> hits(static_cast<std::size_t>(o.coverage_cells_x * o.coverage_cells_y), 0);
  int round = 1;
  while (static_cast<int>(chosen.size()) < o.max_views && !views.empty()) {
    std::size_t best = 0;
    long best_score = -1;
    for (std::size_t i = 0; i < views.size(); ++i) {
      long fresh = 0;
      for (int c : cells_of(views[i], size, o)) fresh += hits[static_cast<std::size_t>(c)] < round;
      const long score = fresh * 10000 + static_cast<long>(views[i].image.size());
      if (score > best_score) {
        best_score = score;
        best = i;
      }
    }
    for (int c : cells_of(views[best], size, o)) ++hits[static_cast<std::size_t>(c)];
    chosen.push_back(std::move(views[best]));
    views.erase(views.begin() + static_cast<std::ptrdiff_t>(best));
    if (std::all_of(hits.begin(), hits.end(), [&](int h) { return h >= round; })) ++round;
  }
  std::sort(chosen.begin(), chosen.end(), [](const ViewData& a, const ViewData& b) { return a.frame < b.frame; });
  return chosen;
}

int radtan_flags(CalibrationModel m) {
  int flags = cv::CALIB_FIX_K3;  // four coefficients, as sensor.yaml holds
  if (m == CalibrationModel::kPinhole) flags |= cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_ZERO_TANGENT_DIST;
  return flags;
}

template <class T>
std::vector<std::vector<T>> column(const std::vector<ViewData>& views, std::vector<T> ViewData::*member) {
  std::vector<std::vector<T>> out;
  for (const auto& v : views) out.push_back(v.*member);
  return out;
}

struct CameraSolve {
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<double> view_rms;
  double rms = 0;
};

double view_rms(const ViewData& v, const cv::Mat& K, const cv::Mat& D, const cv::Mat& r, const cv::Mat& t,
                CalibrationModel model) {
  std::vector<cv::Point2f> projected;
  if (model == CalibrationModel::kEquidistant) cv::fisheye::projectPoints(v.object, projected, r, t, K, D);
  else cv::projectPoints(v.object, r, t, K, D, projected);
  double sum = 0;
  for (std::size_t i = 0; i < projected.size(); ++i) {
    const cv::Point2f e = projected[i] - v.image[i];
    sum += e.dot(e);
  }
  return std::sqrt(sum / static_cast<double>(projected.size()));
}

// OpenCV's fisheye calibration asserts on a view whose initial extrinsics it cannot compute (a
// view seen at a grazing angle through its initial guess of the lens); such views are found one
// by one with the intrinsics held at that guess, and left out.
std::vector<bool> fisheye_initialisable(const std::vector<ViewData>& views, cv::Size size) {
  std::vector<bool> ok;
  for (const auto& v : views) {
    cv::Mat K = (cv::Mat_<double>(3, 3) << std::max(size.width, size.height) / M_PI, 0, (size.width - 1) / 2.0, 0,
                 std::max(size.width, size.height) / M_PI, (size.height - 1) / 2.0, 0, 0, 1);
    cv::Mat D = cv::Mat::zeros(4, 1, CV_64F);
    std::vector<cv::Mat> r, t;
    try {
      cv::fisheye::calibrate(std::vector<std::vector<cv::Point3f>>{v.object}, std::vector<std::vector<cv::Point2f>>{v.image},
                             size, K, D, r, t,
                             cv::fisheye::CALIB_USE_INTRINSIC_GUESS | cv::fisheye::CALIB_FIX_INTRINSIC,
                             cv::TermCriteria(cv::TermCriteria::COUNT, 1, 0));
      ok.push_back(true);
    } catch (const cv::Exception&) {
      ok.push_back(false);
    }
  }
  return ok;
}

CameraSolve solve_camera(std::vector<ViewData>& views, cv::Size size, CalibrationModel model) {
  CameraSolve s;
  if (model == CalibrationModel::kEquidistant) {
    for (int attempt = 0;; ++attempt) {
      s.K = cv::Mat::eye(3, 3, CV_64F);
      s.D = cv::Mat::zeros(4, 1, CV_64F);
      try {
        cv::fisheye::calibrate(column(views, &ViewData::object), column(views, &ViewData::image), size, s.K, s.D,
                               s.rvecs, s.tvecs,
                               cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW, kCriteria);
        break;
      } catch (const cv::Exception& e) {
        const auto ok = fisheye_initialisable(views, size);
        std::vector<ViewData> kept;
        for (std::size_t i = 0; i < views.size(); ++i)
          if (ok[i]) kept.push_back(std::move(views[i]));
        if (attempt > 0 || kept.size() == views.size() || kept.size() < static_cast<std::size_t>(kMinViewsPerCamera)) {
          throw std::runtime_error(std::string("fisheye calibration failed: ") + e.what());
        }
        views = std::move(kept);
      }
    }
  } else {
    const auto object = column(views, &ViewData::object);
    const auto image = column(views, &ViewData::image);
    s.D = cv::Mat::zeros(5, 1, CV_64F);
    cv::calibrateCamera(object, image, size, s.K, s.D, s.rvecs, s.tvecs, radtan_flags(model), kCriteria);
  }
  double sum = 0;
  long n = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    s.view_rms.push_back(view_rms(views[i], s.K, s.D, s.rvecs[i], s.tvecs[i], model));
    sum += s.view_rms.back() * s.view_rms.back() * static_cast<double>(views[i].image.size());
    n += static_cast<long>(views[i].image.size());
  }
  s.rms = std::sqrt(sum / static_cast<double>(n));
  return s;
}

geometry::LensCamera lens_of(const cv::Mat& K, const cv::Mat& D, cv::Size size, CalibrationModel model) {
  geometry::LensCamera l;
  l.model = model == CalibrationModel::kEquidistant ? geometry::LensModel::kEquidistant
                                                   : geometry::LensModel::kRadialTangential;
  l.width = size.width;
  l.height = size.height;
  l.fx = K.at<double>(0, 0);
  l.fy = K.at<double>(1, 1);
  l.cx = K.at<double>(0, 2);
  l.cy = K.at<double>(1, 2);
  for (int i = 0; i < 4; ++i) l.coeffs[static_cast<std::size_t>(i)] = D.at<double>(i);
  return l;
}

struct CameraResult {
  CameraReport report;
  cv::Mat K, D;
};

// Solves, rejects views far above the median error, and solves again until none is rejected.
CameraResult calibrate_camera(std::vector<ViewData> views, cv::Size size, const CalibrationOptions& o,
                              const std::string& source, const char* name) {
  if (static_cast<int>(views.size()) < kMinViewsPerCamera) {
    throw InputError(source, fmt::format("the board is seen with at least {} corners in {} frames of the {} camera, "
                                         "{} are needed", o.min_corners, views.size(), name, kMinViewsPerCamera));
  }
  views = select_for_coverage(std::move(views), size, o);
  CameraResult out;
  CameraSolve s;
  for (int round = 0; round < 4; ++round) {
    try {
      s = solve_camera(views, size, o.model);
    } catch (const std::exception& e) {  // OpenCV's asserts on views it cannot use
      throw InputError(source, fmt::format("the {} camera's calibration failed ({} views): {}", name, views.size(),
                                           e.what()));
    }
    std::vector<double> sorted = s.view_rms;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double limit = std::max(o.outlier_factor * sorted[sorted.size() / 2], o.outlier_floor_px);
    std::vector<ViewData> kept;
    for (std::size_t i = 0; i < views.size(); ++i) {
      if (s.view_rms[i] > limit) out.report.rejected.push_back(views[i].frame);
      else kept.push_back(std::move(views[i]));
    }
    const bool rejected_some = kept.size() < views.size();
    views = std::move(kept);
    if (!rejected_some) break;
    if (static_cast<int>(views.size()) < kMinViewsPerCamera) {
      throw InputError(source, fmt::format("the {} camera keeps only {} views after rejecting outliers", name, views.size()));
    }
  }
  out.K = s.K;
  out.D = s.D;
  CameraReport& r = out.report;
  r.lens = lens_of(s.K, s.D, size, o.model);
  r.rms_px = s.rms;
  r.view_rms_px = s.view_rms;
  std::vector<int> all_cells;
  for (std::size_t i = 0; i < views.size(); ++i) {
    r.views.push_back(views[i].frame);
    for (int c : cells_of(views[i], size, o)) all_cells.push_back(c);
    cv::Mat R;
    cv::Rodrigues(s.rvecs[i], R);
    r.max_tilt_deg = std::max(r.max_tilt_deg, std::acos(std::min(1.0, std::abs(R.at<double>(2, 2)))) * 180.0 / M_PI);
  }
  std::sort(all_cells.begin(), all_cells.end());
  all_cells.erase(std::unique(all_cells.begin(), all_cells.end()), all_cells.end());
  r.covered_share = static_cast<double>(all_cells.size()) / (o.coverage_cells_x * o.coverage_cells_y);
  return out;
}

void warn_about(const CameraReport& r, const char* name, const CalibrationOptions& o, std::vector<std::string>& w) {
  if (r.covered_share < 0.75) {
    w.push_back(fmt::format("{} camera: board corners reach only {:.0f} % of the image's {}x{} cells; move the board "
                            "into the corners and along the edges, where distortion is strongest",
                            name, 100 * r.covered_share, o.coverage_cells_x, o.coverage_cells_y));
  }
  if (r.max_tilt_deg < 25) {
    w.push_back(fmt::format("{} camera: the board is never tilted more than {:.0f} deg; tilt it by 30-50 deg, or the "
                            "focal length and the distance cannot be told apart", name, r.max_tilt_deg));
  }
  if (r.rejected.size() * 5 > r.views.size() + r.rejected.size()) {
    w.push_back(fmt::format("{} camera: {} of {} views rejected as outliers (blur? a board that is not flat?)", name,
                            r.rejected.size(), r.views.size() + r.rejected.size()));
  }
}

// The board's pose in a camera's frame from its corners: PnP on the rays (the lens undone exactly),
// planar (IPPE) and then refined. nullopt with too few corners in front of the camera.
std::optional<Eigen::Isometry3d> board_pose(const geometry::LensCamera& lens, const std::vector<BoardObservation>& seen,
                                            const std::vector<cv::Point3f>& corners) {
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> normalised;
  for (const auto& o : seen) {
    const auto ray = lens.unproject({o.pixel.x, o.pixel.y});
    if (!ray || ray->z() < 0.2) continue;  // beyond 78 degrees the plane of z = 1 is a poor place
    object.push_back(corners.at(static_cast<std::size_t>(o.corner)));
    normalised.emplace_back(static_cast<float>(ray->x() / ray->z()), static_cast<float>(ray->y() / ray->z()));
  }
  if (object.size() < 6) return std::nullopt;
  cv::Mat rvec, tvec;
  const cv::Mat I = cv::Mat::eye(3, 3, CV_64F);
  if (!cv::solvePnP(object, normalised, I, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) return std::nullopt;
  cv::solvePnP(object, normalised, I, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d Re;
  cv::cv2eigen(R, Re);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Re;
  T.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  if (!(T.translation().z() > 0)) return std::nullopt;
  return T;
}

}  // namespace

CalibrationModel parse_calibration_model(const std::string& name) {
  if (name == "pinhole") return CalibrationModel::kPinhole;
  if (name == "radtan" || name == "radial-tangential") return CalibrationModel::kRadialTangential;
  if (name == "equidistant" || name == "fisheye") return CalibrationModel::kEquidistant;
  throw InputError("--model", "unknown camera model '" + name + "' (expected pinhole, radtan or equidistant)");
}

const char* to_string(CalibrationModel model) {
  switch (model) {
    case CalibrationModel::kPinhole: return "pinhole";
    case CalibrationModel::kRadialTangential: return "radtan";
    case CalibrationModel::kEquidistant: return "equidistant";
  }
  return "?";
}

StereoCalibrationResult calibrate_stereo(const std::vector<StereoView>& views, const BoardSpec& board,
                                         cv::Size image_size, const CalibrationOptions& o, const std::string& source) {
  const auto corners = board.corners();
  std::vector<ViewData> left, right;
  for (const auto& v : views) {
    for (auto [detection, list] : {std::pair{&v.left, &left}, std::pair{&v.right, &right}}) {
      if (static_cast<int>(detection->ids.size()) < o.min_corners) continue;
      ViewData data = view_data(v.frame, *detection, corners);
      if (spans_the_board(data, board.square_m)) list->push_back(std::move(data));
    }
  }
  StereoCalibrationResult result;
  CameraResult l = calibrate_camera(std::move(left), image_size, o, source, "left");
  CameraResult r = calibrate_camera(std::move(right), image_size, o, source, "right");
  // The joint solve: every view either camera kept, with the corners of each camera that saw the
  // board well enough; each view's board pose starts from PnP in one of the cameras.
  std::vector<RigView> rig_views;
  std::vector<int> rig_frames;
  std::vector<bool> in_right_frame;
  std::vector<Eigen::Quaterniond> rig_rotations;
  Eigen::Vector3d rig_translation = Eigen::Vector3d::Zero();
  for (const auto& v : views) {
    auto kept = [&](const CameraReport& c) { return std::find(c.views.begin(), c.views.end(), v.frame) != c.views.end(); };
    const bool in_left = kept(l.report), in_right = kept(r.report);
    if (!in_left && !in_right) continue;
    RigView rv;
    if (in_left) for (std::size_t i = 0; i < v.left.ids.size(); ++i) rv.left.push_back({v.left.ids[i], v.left.pixels[i]});
    if (in_right) for (std::size_t i = 0; i < v.right.ids.size(); ++i) rv.right.push_back({v.right.ids[i], v.right.pixels[i]});
    const auto pose_l = in_left ? board_pose(l.report.lens, rv.left, corners) : std::nullopt;
    const auto pose_r = in_right ? board_pose(r.report.lens, rv.right, corners) : std::nullopt;
    if (pose_l && pose_r) {
      const Eigen::Isometry3d T = *pose_r * pose_l->inverse();
      Eigen::Quaterniond q(T.rotation());
      if (!rig_rotations.empty() && q.dot(rig_rotations.front()) < 0) q.coeffs() *= -1;
      rig_rotations.push_back(q);
      rig_translation += T.translation();
      result.stereo_views.push_back(v.frame);
    }
    if (!pose_l && !pose_r) continue;
    if (!pose_l) rv.left.clear();
    rv.T_left_board = pose_l ? *pose_l : *pose_r;  // a pose in the right camera is moved below, once the rig is known
    in_right_frame.push_back(!pose_l);
    rig_views.push_back(std::move(rv));
    rig_frames.push_back(v.frame);
  }
  if (static_cast<int>(rig_rotations.size()) < kMinStereoViews) {
    throw InputError(source, fmt::format("both cameras see the board with at least {} corners in {} frames, {} are "
                                         "needed (are the pairs synchronised?)", o.min_corners, rig_rotations.size(),
                                         kMinStereoViews));
  }
  Eigen::Vector4d mean_q = Eigen::Vector4d::Zero();
  for (const auto& q : rig_rotations) mean_q += q.coeffs();
  Eigen::Isometry3d T_rl = Eigen::Isometry3d::Identity();
  T_rl.linear() = Eigen::Quaterniond(mean_q.normalized()).toRotationMatrix();
  T_rl.translation() = rig_translation / static_cast<double>(rig_rotations.size());
  for (std::size_t i = 0; i < rig_views.size(); ++i) {
    if (in_right_frame[i]) rig_views[i].T_left_board = T_rl.inverse() * rig_views[i].T_left_board;
  }
  const RigRefinement refined = refine_rig(l.report.lens, r.report.lens, T_rl, rig_views, corners,
                                           o.model == CalibrationModel::kPinhole);
  if (!refined.converged || !std::isfinite(refined.rms_px)) {
    throw InputError(source, "the stereo calibration did not converge (unsynchronised pairs, or a rig that moved?)");
  }
  l.report.lens = refined.left;
  r.report.lens = refined.right;
  const double own_rms = std::max(l.report.rms_px, r.report.rms_px);
  for (auto [report, errors] : {std::pair{&l.report, &refined.left_errors}, std::pair{&r.report, &refined.right_errors}}) {
    double sum = 0;
    for (const auto& e : *errors) {
      report->corners.push_back({rig_frames.at(static_cast<std::size_t>(e.view)), e.pixel, e.error});
      sum += e.error.dot(e.error);
    }
    if (!errors->empty()) report->rms_px = std::sqrt(sum / static_cast<double>(errors->size()));
  }
  // Each camera alone fits its views; if the two cannot be fitted together with one rig, the
  // images of a pair were not taken at the same moment (or the rig flexed).
  const double joint_rms = std::max(l.report.rms_px, r.report.rms_px);
  if (joint_rms > std::max(2.0 * own_rms, own_rms + 0.5)) {
    throw InputError(source, fmt::format("the cameras' views of the board disagree: {:.2f} px RMS with one rig for "
                                         "both, against {:.2f} px for each alone (unsynchronised pairs, or a rig "
                                         "that moved?)", joint_rms, own_rms));
  }
  result.T_right_left = refined.T_right_left;
  result.stereo_rms_px = refined.rms_px;
  result.left = std::move(l.report);
  result.right = std::move(r.report);
  warn_about(result.left, "left", o, result.warnings);
  warn_about(result.right, "right", o, result.warnings);
  return result;
}

}  // namespace plslam::calib
