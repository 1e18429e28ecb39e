#include "plslam/calib/calibration_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace plslam::calib {

nlohmann::json lens_json(const geometry::LensCamera& l) {
  return {{"distortion_model", geometry::to_string(l.model)},
          {"intrinsics", {l.fx, l.fy, l.cx, l.cy}},
          {"distortion_coeffs", {l.coeffs[0], l.coeffs[1], l.coeffs[2], l.coeffs[3]}},
          {"resolution", {l.width, l.height}}};
}

nlohmann::json transform_json(const Eigen::Isometry3d& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({T.matrix()(r, 0), T.matrix()(r, 1), T.matrix()(r, 2), T.matrix()(r, 3)});
  return rows;
}

namespace {

double angle_deg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

nlohmann::json camera_json(const CameraReport& c) {
  nlohmann::json j = lens_json(c.lens);
  j["rms_px"] = c.rms_px;
  j["views"] = c.views;
  j["rejected_views"] = c.rejected;
  j["covered_share"] = c.covered_share;
  j["max_tilt_deg"] = c.max_tilt_deg;
  j["corners"] = c.corners.size();
  return j;
}

// The largest distance between the pixels two lenses give the same ray, over a grid of the
// first lens's image (where it unprojects).
double worst_pixel_difference(const geometry::LensCamera& a, const geometry::LensCamera& b) {
  double worst = 0;
  for (int y = 0; y <= 20; ++y) {
    for (int x = 0; x <= 20; ++x) {
      const Eigen::Vector2d p((a.width - 1) * x / 20.0, (a.height - 1) * y / 20.0);
      const auto ray = a.unproject(p);
      if (!ray) continue;
      const auto q = b.project(*ray);
      if (!q) return INFINITY;
      worst = std::max(worst, (*q - p).norm());
    }
  }
  return worst;
}

nlohmann::json lens_error_json(const geometry::LensCamera& e, const geometry::LensCamera& t) {
  return {{"fx_percent", 100 * (e.fx - t.fx) / t.fx},
          {"fy_percent", 100 * (e.fy - t.fy) / t.fy},
          {"cx_px", e.cx - t.cx},
          {"cy_px", e.cy - t.cy},
          {"distortion_coeffs", {e.coeffs[0] - t.coeffs[0], e.coeffs[1] - t.coeffs[1], e.coeffs[2] - t.coeffs[2],
                                 e.coeffs[3] - t.coeffs[3]}},
          {"true_distortion_coeffs", {t.coeffs[0], t.coeffs[1], t.coeffs[2], t.coeffs[3]}},
          {"worst_pixel_difference", worst_pixel_difference(t, e)}};
}

cv::Scalar error_colour(double px) {
  if (px < 0.3) return {60, 200, 60};
  if (px < 1.0) return {0, 210, 230};
  return {40, 40, 230};
}

void draw_camera(cv::Mat panel, const CameraReport& c, const char* name, const CalibrationOptions& o) {
  panel.setTo(cv::Scalar(40, 40, 40));
  std::vector<int> hit(static_cast<std::size_t>(o.coverage_cells_x * o.coverage_cells_y), 0);
  for (const auto& k : c.corners) {
    const int cx = std::clamp(static_cast<int>(k.pixel.x * o.coverage_cells_x / panel.cols), 0, o.coverage_cells_x - 1);
    const int cy = std::clamp(static_cast<int>(k.pixel.y * o.coverage_cells_y / panel.rows), 0, o.coverage_cells_y - 1);
    ++hit[static_cast<std::size_t>(cy * o.coverage_cells_x + cx)];
  }
  for (int cy = 0; cy < o.coverage_cells_y; ++cy) {
    for (int cx = 0; cx < o.coverage_cells_x; ++cx) {
      const cv::Rect cell(cx * panel.cols / o.coverage_cells_x, cy * panel.rows / o.coverage_cells_y,
                          panel.cols / o.coverage_cells_x, panel.rows / o.coverage_cells_y);
      const bool covered = hit[static_cast<std::size_t>(cy * o.coverage_cells_x + cx)] > 0;
      cv::rectangle(panel, cell, covered ? cv::Scalar(50, 80, 50) : cv::Scalar(50, 50, 110), cv::FILLED);
      cv::rectangle(panel, cell, cv::Scalar(90, 90, 90), 1);
    }
  }
  for (const auto& k : c.corners) {
    const double e = std::hypot(k.error.x, k.error.y);
    cv::line(panel, k.pixel, k.pixel + 50.0f * k.error, error_colour(e), 1, cv::LINE_AA);
    cv::circle(panel, k.pixel, 1, error_colour(e), cv::FILLED, cv::LINE_AA);
  }
  const std::string caption = fmt::format("{}: rms {:.2f} px, {} views, {:.0f} % of cells, tilt up to {:.0f} deg", name,
                                          c.rms_px, c.views.size(), 100 * c.covered_share, c.max_tilt_deg);
  const double scale = std::max(0.4, panel.cols / 1400.0);
  cv::putText(panel, caption, {8, static_cast<int>(22 * scale / 0.5)}, cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  cv::putText(panel, "errors drawn x50: green < 0.3 px, yellow < 1 px, red above", {8, panel.rows - 10},
              cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(220, 220, 220), 1, cv::LINE_AA);
}

}  // namespace

geometry::RawStereoRig rig_of(const StereoCalibrationResult& r) { return {r.left.lens, r.right.lens, r.T_right_left}; }

nlohmann::json calibration_json(const StereoCalibrationResult& r) {
  return {{"cam0", camera_json(r.left)},
          {"cam1", camera_json(r.right)},
          {"stereo",
           {{"T_cn_cnm1", transform_json(r.T_right_left)},
            {"baseline_m", r.T_right_left.translation().norm()},
            {"rotation_deg", angle_deg(r.T_right_left.rotation())},
            {"rms_px", r.stereo_rms_px},
            {"views_in_both", r.stereo_views.size()}}},
          {"warnings", r.warnings}};
}

nlohmann::json calibration_error_json(const geometry::RawStereoRig& e, const geometry::RawStereoRig& t) {
  const double baseline = t.T_right_left.translation().norm();
  return {{"cam0", lens_error_json(e.left, t.left)},
          {"cam1", lens_error_json(e.right, t.right)},
          {"baseline_percent", 100 * (e.T_right_left.translation().norm() - baseline) / baseline},
          {"rotation_deg", angle_deg(e.T_right_left.rotation() * t.T_right_left.rotation().transpose())}};
}

cv::Mat draw_coverage(const StereoCalibrationResult& r, cv::Size size, const CalibrationOptions& o) {
  cv::Mat out(size.height, 2 * size.width, CV_8UC3);
  draw_camera(out(cv::Rect(0, 0, size.width, size.height)), r.left, "left (cam0)", o);
  draw_camera(out(cv::Rect(size.width, 0, size.width, size.height)), r.right, "right (cam1)", o);
  return out;
}

}  // namespace plslam::calib
