#include "plslam/bench/slam_figures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "plslam/eval/chart.h"
#include "plslam/eval/plots.h"
#include "plslam/eval/rpe.h"

namespace plslam::bench {
namespace fs = std::filesystem;

namespace {

// matplotlib's tab10 in BGR; the ground truth is drawn in black.
const std::array<cv::Scalar, 10> kPalette = {
    cv::Scalar(180, 119, 31), cv::Scalar(14, 127, 255), cv::Scalar(44, 160, 44),  cv::Scalar(40, 39, 214),
    cv::Scalar(189, 103, 148), cv::Scalar(75, 86, 140), cv::Scalar(194, 119, 227), cv::Scalar(127, 127, 127),
    cv::Scalar(34, 189, 188), cv::Scalar(207, 190, 23)};
const cv::Scalar kBlack(0, 0, 0);

cv::Scalar colour(std::size_t i) { return kPalette[i % kPalette.size()]; }

std::vector<cv::Point2d> project(const Trajectory& t, const std::function<cv::Point2d(const Eigen::Vector3d&)>& f) {
  std::vector<cv::Point2d> out;
  out.reserve(t.size());
  for (const auto& p : t) out.push_back(f(p.T.translation()));
  return out;
}

// The estimate moved so that its first paired pose coincides with the ground truth's: what the
// run itself reports, without a fitted alignment.
Trajectory at_first_pose(const FigureRun& run, const Trajectory& gt) {
  Trajectory out;
  const auto& pairs = run.result.pairs;
  if (pairs.size() == 0) return out;
  const Eigen::Isometry3d fix = gt[pairs.gt.front()].T * run.estimate[pairs.est.front()].T.inverse();
  for (const std::size_t e : pairs.est) {
    StampedPose p;
    p.t = run.estimate[e].t;
    p.T = fix * run.estimate[e].T;
    out.push_back(p);
  }
  return out;
}


using Projection = std::function<cv::Point2d(const Eigen::Vector3d&)>;
using NamedTrajectories = std::vector<std::pair<std::string, Trajectory>>;

// The ground truth (dashed black) and each row's trajectory, one metre as long on both axes.
void draw_trajectories(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                       const Trajectory& gt, const NamedTrajectories& est, const Projection& f, const fs::path& path) {
  eval::Chart c;
  c.set_title(title);
  c.set_xlabel(xlabel);
  c.set_ylabel(ylabel);
  c.set_equal_aspect(true);
  c.add_line(project(gt, f), {kBlack, 2, true}, "ground truth");
  for (std::size_t i = 0; i < est.size(); ++i) c.add_line(project(est[i].second, f), {colour(i), 2, false}, est[i].first);
  cv::Mat img(900, 1000, CV_8UC3, cv::Scalar(255, 255, 255));
  c.draw(img);
  eval::save_png(img, path);
}

void top_view(const std::string& title, const Trajectory& gt, const NamedTrajectories& est, const fs::path& path) {
  const auto [a, b] = eval::top_view_axes(gt);
  const char* names = "xyz";
  draw_trajectories(title, fmt::format("{} [m]", names[a]), fmt::format("{} [m]", names[b]), gt, est,
                    [a = a, b = b](const Eigen::Vector3d& p) { return cv::Point2d(p[a], p[b]); }, path);
}

// An oblique parallel projection: azimuth 35 deg about the vertical axis, elevation 25 deg.
void view_3d(const std::string& title, const Trajectory& gt, const NamedTrajectories& est, const fs::path& path) {
  const auto [a, b] = eval::top_view_axes(gt);
  const int up = 3 - a - b;
  const double az = 35.0 * M_PI / 180, el = 25.0 * M_PI / 180;
  auto f = [a = a, b = b, up, az, el](const Eigen::Vector3d& p) {
    const double x = std::cos(az) * p[a] - std::sin(az) * p[b];
    const double depth = std::sin(az) * p[a] + std::cos(az) * p[b];
    const double y = std::cos(el) * p[up] + std::sin(el) * depth;
    return cv::Point2d(x, y);
  };
  draw_trajectories(title, "oblique view, horizontal [m]", "oblique view, vertical [m]", gt, est, f, path);
}

}  // namespace

std::vector<double> read_frame_times(const fs::path& folder) {
  std::vector<double> out;
  if (std::ifstream in(folder / "frames.csv"); in) {
    std::string line;
    if (!std::getline(in, line)) return out;
    int column = -1, i = 0;
    std::stringstream header(line);
    for (std::string name; std::getline(header, name, ','); ++i) {
      if (name == "tracking_ms") column = i;
    }
    if (column < 0) return out;
    while (std::getline(in, line)) {
      std::stringstream row(line);
      std::string v;
      for (int k = 0; k <= column && std::getline(row, v, ','); ++k) {
      }
      try {
        out.push_back(std::stod(v));
      } catch (const std::exception&) {
        return {};  // a malformed file plots nothing rather than a wrong curve
      }
    }
    return out;
  }
  if (std::ifstream in(folder / "frame_times_ms.txt"); in) {
    for (double v; in >> v;) out.push_back(v);
  }
  return out;
}

std::vector<std::string> write_dataset_figures(const fs::path& dir, const std::string& dataset, const Trajectory& gt,
                                               const std::vector<FigureRun>& runs) {
  std::vector<std::string> written;
  NamedTrajectories aligned, first_pose;
  for (const auto& r : runs) {
    aligned.emplace_back(r.row, r.result.est);
    first_pose.emplace_back(r.row, at_first_pose(r, gt));
  }
  const std::string x_label = "time [s]";

  auto name = [&](const char* what) { return fmt::format("{}_{}.png", dataset, what); };
  top_view(dataset + ": top view, SE(3)-aligned (median-ATE run of each row)", gt, aligned, dir / name("trajectory"));
  written.push_back(name("trajectory"));
  top_view(dataset + ": top view, aligned at the first pose only (no Umeyama)", gt, first_pose,
           dir / name("trajectory_first_pose"));
  written.push_back(name("trajectory_first_pose"));
  view_3d(dataset + ": 3D view, SE(3)-aligned", gt, aligned, dir / name("trajectory_3d"));
  written.push_back(name("trajectory_3d"));

  {  // translation and rotation error over time, two panels
    // A row that failed (ATE over 5x the median row's) would flatten every other curve: it is
    // left out here and named in the title; the trajectory figures show it.
    std::vector<double> ates;
    for (const auto& r : runs) ates.push_back(r.result.ape_trans_stats.rmse);
    std::vector<double> sorted = ates;
    std::sort(sorted.begin(), sorted.end());
    const double median_ate = sorted[(sorted.size() - 1) / 2];
    std::string left_out;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (ates[i] > 5 * median_ate) left_out += (left_out.empty() ? "" : ", ") + runs[i].row;
    }
    const std::string note = left_out.empty() ? "" : " (not drawn, ATE > 5x the median row's: " + left_out + ")";
    eval::Chart ct, cr;
    ct.set_title(dataset + ": translation error over time (SE(3)-aligned)" + note);
    ct.set_xlabel(x_label);
    ct.set_ylabel("APE [m]");
    ct.set_y_from_zero(true);
    cr.set_title(dataset + ": rotation drift since the first pose");
    cr.set_xlabel(x_label);
    cr.set_ylabel("rotation drift [deg]");
    cr.set_y_from_zero(true);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (ates[i] > 5 * median_ate) continue;
      const auto& r = runs[i].result;
      std::vector<cv::Point2d> pt, pr;
      for (std::size_t k = 0; k < r.est.size(); ++k) {
        const double x = r.gt[k].t - r.gt.front().t;
        pt.emplace_back(x, r.ape_trans_m[k]);
        // Rotation drift since the first pose: free of the alignment, whose rotation a short or
        // straight path leaves undetermined (EuRoC micro moves about a millimetre).
        const Eigen::Matrix3d gt_rel = r.gt.front().T.linear().transpose() * r.gt[k].T.linear();
        const Eigen::Matrix3d est_rel = r.est.front().T.linear().transpose() * r.est[k].T.linear();
        pr.emplace_back(x, eval::rotation_angle(gt_rel.transpose() * est_rel) * 180.0 / M_PI);
      }
      ct.add_line(pt, {colour(i), 2, false}, runs[i].row);
      cr.add_line(pr, {colour(i), 2, false}, runs[i].row);
    }
    cv::Mat img(1200, 1200, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::Mat top = img(cv::Rect(0, 0, 1200, 600)), bottom = img(cv::Rect(0, 600, 1200, 600));
    ct.draw(top);
    cr.draw(bottom);
    eval::save_png(img, dir / name("errors"));
    written.push_back(name("errors"));
  }
  {  // tracking time per frame
    eval::Chart c;
    c.set_title(dataset + ": tracking time per frame (median-ATE run of each row)");
    c.set_xlabel("frame");
    c.set_ylabel("tracking [ms]");
    c.set_y_from_zero(true);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      std::vector<cv::Point2d> p;
      for (std::size_t k = 0; k < runs[i].frame_ms.size(); ++k) p.emplace_back(static_cast<double>(k), runs[i].frame_ms[k]);
      if (!p.empty()) c.add_line(p, {colour(i), 1, false}, runs[i].row);
    }
    cv::Mat img(700, 1400, CV_8UC3, cv::Scalar(255, 255, 255));
    c.draw(img);
    eval::save_png(img, dir / name("tracking_ms"));
    written.push_back(name("tracking_ms"));
  }
  return written;
}

std::string write_keyframe_bars(const fs::path& dir, const nlohmann::json& summary,
                                const std::vector<BenchDataset>& datasets, const std::vector<BenchRow>& rows) {
  const int width = std::max(900, 140 + static_cast<int>(datasets.size() * (rows.size() * 26 + 40))), height = 700;
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 260, top = 60, bottom = 110;
  const cv::Rect plot(left, top, width - left - right, height - top - bottom);
  double max_kf = 1;
  for (const auto& d : datasets) {
    for (const auto& r : rows) {
      const auto& s = summary[d.name][r.name]["keyframes"];
      if (s.is_object()) max_kf = std::max(max_kf, s["max"].get<double>());
    }
  }
  const auto ticks = eval::nice_ticks(0, 1.1 * max_kf, 6);
  const double y_max = std::max(1.1 * max_kf, ticks.empty() ? max_kf : ticks.back());
  auto y_of = [&](double v) { return plot.y + plot.height - static_cast<int>(std::lround(v / y_max * plot.height)); };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, "Keyframes per dataset and configuration (bars: median, whiskers: min-max)", {left, 35}, font, 0.7, kBlack, 2,
              cv::LINE_AA);
  for (double t : ticks) {
    if (t > y_max) continue;
    cv::line(img, {plot.x, y_of(t)}, {plot.x + plot.width, y_of(t)}, cv::Scalar(225, 225, 225), 1);
    cv::putText(img, fmt::format("{:g}", t == 0 ? 0.0 : t), {10, y_of(t) + 5}, font, 0.5, kBlack, 1, cv::LINE_AA);
  }
  cv::rectangle(img, plot, kBlack, 1);
  const double group = static_cast<double>(plot.width) / std::max<std::size_t>(1, datasets.size());
  const double bar = std::min(26.0, (group - 20) / std::max<std::size_t>(1, rows.size()));
  for (std::size_t d = 0; d < datasets.size(); ++d) {
    const double x0 = plot.x + group * static_cast<double>(d) + (group - bar * static_cast<double>(rows.size())) / 2;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const auto& s = summary[datasets[d].name][rows[r].name]["keyframes"];
      if (!s.is_object()) continue;
      const int xa = static_cast<int>(x0 + bar * static_cast<double>(r)), xb = static_cast<int>(x0 + bar * static_cast<double>(r + 1)) - 2;
      cv::rectangle(img, cv::Point(xa, y_of(s["median"].get<double>())), cv::Point(xb, plot.y + plot.height), colour(r),
                    cv::FILLED);
      const int xm = (xa + xb) / 2;
      cv::line(img, {xm, y_of(s["min"].get<double>())}, {xm, y_of(s["max"].get<double>())}, kBlack, 1);
    }
    cv::putText(img, datasets[d].name, {static_cast<int>(x0), plot.y + plot.height + 25}, font, 0.5, kBlack, 1, cv::LINE_AA);
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int y = top + 20 + static_cast<int>(r) * 24;
    cv::rectangle(img, cv::Rect(width - right + 15, y - 12, 18, 14), colour(r), cv::FILLED);
    cv::putText(img, rows[r].name, {width - right + 40, y}, font, 0.5, kBlack, 1, cv::LINE_AA);
  }
  eval::save_png(img, dir / "keyframes.png");
  return "keyframes.png";
}

}  // namespace plslam::bench
